// One WebSocket to the bridge at /ws, reconnecting with backoff. Messages are
// dispatched by their `type` to handlers registered with on().
import { checkCommand } from './protocol.js';

export class Connection {
  constructor(url, { fps = 30, rays = false } = {}) {
    this.url = url;
    this.sub = { fps, rays };
    this.handlers = new Map();
    this.ws = null;
    this.state = 'connecting';  // 'connecting' | 'open' | 'closed'
    this.nextId = 1;
    this.retryMs = 500;
    this.received = 0;
    this.sentCommands = new Map();  // id -> {cmd, args, at}
  }

  on(type, fn) {
    if (!this.handlers.has(type)) this.handlers.set(type, []);
    this.handlers.get(type).push(fn);
    return this;
  }

  emit(type, msg) {
    for (const fn of this.handlers.get(type) ?? []) fn(msg);
  }

  connect() {
    this.setState('connecting');
    let ws;
    try {
      ws = new WebSocket(this.url);
    } catch (e) {
      this.emit('log', { level: 'bad', text: `cannot open ${this.url}: ${e.message}` });
      this.retry();
      return;
    }
    this.ws = ws;
    ws.onopen = () => {
      this.retryMs = 500;
      this.setState('open');
      this.send({ type: 'subscribe', fps: this.sub.fps, rays: this.sub.rays });
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data !== 'string') return;
      let msg;
      try {
        msg = JSON.parse(ev.data);
      } catch {
        this.emit('log', { level: 'bad', text: 'bridge sent a frame that is not JSON' });
        return;
      }
      this.received++;
      if (msg && typeof msg.type === 'string') this.emit(msg.type, msg);
    };
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this.ws = null;
      this.setState('closed');
      this.retry();
    };
    ws.onerror = () => {};  // onclose follows
  }

  retry() {
    clearTimeout(this.retryTimer);
    this.retryTimer = setTimeout(() => this.connect(), this.retryMs);
    this.retryMs = Math.min(this.retryMs * 2, 5000);
  }

  setState(s) {
    this.state = s;
    this.emit('state', s);
  }

  get open() { return this.state === 'open'; }

  send(obj) {
    if (!this.ws || this.ws.readyState !== WebSocket.OPEN) return false;
    this.ws.send(JSON.stringify(obj));
    return true;
  }

  subscribe(changes) {
    Object.assign(this.sub, changes);
    this.send({ type: 'subscribe', fps: this.sub.fps, rays: this.sub.rays });
  }

  // Sends a mission command; returns its id, or throws with a one-line reason.
  command(cmd, args = {}) {
    const err = checkCommand(cmd, args);
    if (err) throw new Error(err);
    if (!this.open) throw new Error(`${cmd}: not connected to the bridge`);
    const id = this.nextId++;
    this.sentCommands.set(id, { cmd, args, at: performance.now() });
    this.send({ type: 'command', id, cmd, ...args });
    return id;
  }
}
