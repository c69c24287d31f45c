// throttle.js — rate limiting for controls that change continuously (the
// colour input, transfer-function drags): at most one call per `ms`, the
// first at once and the newest always delivered (trailing), like the
// camera's move messages. No DOM; any module.

// Returns send(final): calls fn() now when `ms` have passed since the last
// call or when `final` (the end of a drag), else once when they have.
// send.pending() is true while a call waits for its turn: an editor shows no
// value from the server then, or the echo of an older edit would replace the
// newer one before it is sent.
export function throttle(fn, ms) {
  let last = 0, timer = null;
  const send = (final = false) => {
    clearTimeout(timer);
    timer = null;
    const wait = last + ms - performance.now();
    if (final || wait <= 0) { last = performance.now(); fn(); return; }
    timer = setTimeout(() => { timer = null; last = performance.now(); fn(); }, wait);
  };
  send.pending = () => timer !== null;
  return send;
}
