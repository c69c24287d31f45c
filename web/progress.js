// progress.js — the bar over the last frame while the server loads a dataset,
// prepares a technique or renders the first frame of it (`progress` messages,
// proto/PROTOCOL.md). A fraction fills the bar; without one (null) the bar
// runs indeterminate. `done` hides it and keeps the round's load and prepare
// times and the backend that drew it (gl, embree: techniques with two executions) for the status line. It draws nothing else and sends nothing.

const LABELS = { loading: 'Loading', preparing: 'Preparing', first_frame: 'Rendering the first frame of' };

export class ProgressOverlay {
  constructor(root) {
    this.root = root;
    this.label = root.querySelector('.label');
    this.fill = root.querySelector('.fill');
    this.stage = null;          // the stage shown, null when hidden
    this.round = 0;
    this.since = 0;             // performance.now() at the round's start (from elapsed_ms)
    this.text = '';
    this.timings = null;        // {loadMs, prepareMs} of the last finished round
    setInterval(() => this.tick(), 250);
  }

  update(msg) {
    if (msg.stage === 'done') {
      if (msg.round === this.round || this.stage === null) this.hide();
      this.timings = { loadMs: msg.load_ms, prepareMs: msg.prepare_ms, backend: msg.backend || null };
      return;
    }
    this.round = msg.round;
    this.stage = msg.stage;
    this.since = performance.now() - (msg.elapsed_ms || 0);
    const what = msg.stage === 'loading' ? msg.dataset : `${msg.dataset} (${msg.technique})`;
    this.text = `${LABELS[msg.stage] || msg.stage} ${what}`;
    const known = typeof msg.fraction === 'number';
    this.root.classList.toggle('indeterminate', !known);
    this.fill.style.width = known ? `${Math.round(msg.fraction * 100)}%` : '';
    this.root.hidden = false;
    this.tick();
  }

  hide() {
    this.stage = null;
    this.root.hidden = true;
  }

  tick() {
    if (this.stage === null) return;
    this.label.textContent = `${this.text}… ${((performance.now() - this.since) / 1000).toFixed(1)} s`;
  }
}
