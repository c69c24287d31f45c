// protocol.js — the sightline.v1 connection (proto/PROTOCOL.md): hello/welcome,
// JSON messages, binary frame headers, automatic reconnect to the same session.
// It does not draw or build UI; app.js listens to its events.
// The session id also goes into the WebSocket URL's query (/ws?session=ID), so
// a balancer in front of several nodes can route a join or a reconnect to the
// node that has the session; the server ignores it (hello is the authority).
// A node that is shutting down answers a new session with `draining` and
// closes: that is a lost connection like any other, retried with backoff
// (through the balancer it reaches another node).

export const SUBPROTOCOL = 'sightline.v1';
export const FRAME_HEADER_SIZE = 40;
const FRAME_MAGIC = 0x31464c53; // "SLF1"

// Parses the 40-byte little-endian frame header; throws on a malformed one.
export function parseFrameHeader(buf) {
  if (buf.byteLength < FRAME_HEADER_SIZE) throw new Error('frame shorter than its header');
  const v = new DataView(buf);
  if (v.getUint32(0, true) !== FRAME_MAGIC) throw new Error('bad frame magic');
  if (v.getUint16(4, true) !== FRAME_HEADER_SIZE) throw new Error('bad frame header size');
  const h = {
    kind: v.getUint8(6) === 1 ? 'png' : 'jpeg',
    interactive: (v.getUint8(7) & 1) !== 0,
    frameId: v.getUint32(8, true),
    stateVersion: v.getUint32(12, true),
    width: v.getUint16(16, true),
    height: v.getUint16(18, true),
    quality: v.getUint8(20),
    subsampling: v.getUint8(21) ? '4:2:0' : '4:4:4',
    renderMs: v.getFloat32(24, true),
    encodeMs: v.getFloat32(28, true),
    cameraSeq: v.getUint32(32, true),
    payloadBytes: v.getUint32(36, true),
  };
  if (h.payloadBytes !== buf.byteLength - FRAME_HEADER_SIZE) throw new Error('frame payload size mismatch');
  return h;
}

// One logical connection that survives socket drops: it reconnects with the
// session id and token it was welcomed with.
export class Connection extends EventTarget {
  constructor({ session = null, token = null, width = 640, height = 480 } = {}) {
    super();
    this.session = session;
    this.token = token;
    this.width = width;
    this.height = height;
    this.ws = null;
    this.retry = 0;
    this.closedByUser = false;
  }

  open() {
    const url = new URL('ws', location.href);
    url.protocol = location.protocol === 'https:' ? 'wss:' : 'ws:';
    url.pathname = '/ws';
    url.hash = '';
    url.search = this.session ? `?session=${encodeURIComponent(this.session)}` : '';
    const ws = new WebSocket(url.toString(), SUBPROTOCOL);
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    ws.onopen = () => {
      const hello = { type: 'hello', version: 1, width: this.width, height: this.height };
      if (this.session) { hello.session = this.session; hello.token = this.token; }
      ws.send(JSON.stringify(hello));
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data === 'string') {
        let msg;
        try { msg = JSON.parse(ev.data); } catch { return; }
        if (msg.type === 'welcome') {
          this.session = msg.session;
          this.token = msg.token;
          this.retry = 0;
        }
        const badLink = msg.code === 'bad_field' && (msg.field === 'session' || msg.field === 'token');
        if (msg.type === 'error' && (msg.code === 'unknown_session' || msg.code === 'bad_token' || badLink)) {
          // The session expired or the link is wrong: start a fresh one on the next connect.
          this.session = null;
          this.token = null;
        }
        this.dispatchEvent(new CustomEvent('message', { detail: msg }));
      } else {
        let header;
        try { header = parseFrameHeader(ev.data); } catch (e) { console.warn(e); return; }
        const payload = new Uint8Array(ev.data, FRAME_HEADER_SIZE);
        this.dispatchEvent(new CustomEvent('frame', { detail: { header, payload } }));
      }
    };
    ws.onclose = (ev) => {
      this.dispatchEvent(new CustomEvent('disconnect', { detail: { code: ev.code, reason: ev.reason } }));
      if (this.closedByUser) return;
      const delay = Math.min(5000, 500 * 2 ** this.retry++);
      setTimeout(() => this.open(), delay);
    };
  }

  send(msg) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify(msg));
      return true;
    }
    return false;
  }

  close() {
    this.closedByUser = true;
    if (this.ws) this.ws.close();
  }
}
