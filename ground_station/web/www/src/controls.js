// The mission controls (the CLI's subcommands as buttons), keyboard teleop
// while following, and the recording player.
const $ = (id) => document.getElementById(id);
const num = (id) => Number($(id).value);

const KEYS = {
  w: [0, 1, 0], arrowup: [0, 1, 0], s: [0, -1, 0], arrowdown: [0, -1, 0],
  a: [-1, 0, 0], arrowleft: [-1, 0, 0], d: [1, 0, 0], arrowright: [1, 0, 0],
  r: [0, 0, 1], f: [0, 0, -1],
};

export class Controls {
  constructor(conn, panel) {
    this.conn = conn;
    this.panel = panel;
    this.following = false;
    this.keys = new Set();
    this.lastTeleop = [0, 0, 0];
    this.lastAck = null;
    this.source = 'live';
    this.replay = null;
    this.seeking = false;

    const send = (cmd, args, what) => this.send(cmd, args, what);
    $('c-takeoff').onclick = () => send('takeoff', { altitude: num('i-alt') }, `takeoff to ${num('i-alt')} m`);
    $('c-move').onclick = () => {
      const v = [num('i-vx'), num('i-vy'), num('i-vz')];
      send('move', { v, duration: num('i-dur') }, `move (${v.join(', ')}) m/s for ${num('i-dur')} s`);
    };
    $('c-land').onclick = () => send('land', {}, 'land');
    $('c-hold').onclick = () => send('hold', {}, 'hold');
    $('c-task').onclick = () => send('task', { speed: num('i-speed'), epsilon: 0 }, `task at ${num('i-speed')} m/s`);
    $('c-follow').onclick = () => send('follow', { leader: num('i-leader') }, `follow leader ${num('i-leader')}`);
    const dist = $('i-dist');
    dist.oninput = () => { $('o-dist').textContent = `${Number(dist.value).toFixed(1)} m`; };
    dist.onchange = () => send('distance', { value: Number(dist.value) }, `inter-drone distance ${dist.value} m`);

    window.addEventListener('keydown', (e) => this.key(e, true));
    window.addEventListener('keyup', (e) => this.key(e, false));
    window.addEventListener('blur', () => { this.keys.clear(); this.teleop(); });

    // Recording.
    $('i-rec').onchange = (e) => { const f = e.target.files?.[0]; e.target.value = ''; if (f) this.upload(f); };
    $('rp-play').onclick = () => this.conn.send({ type: 'replay', action: this.replay?.playing ? 'pause' : 'play' });
    const seek = $('rp-seek');
    seek.oninput = () => {
      this.seeking = true;
      this.showReplayTime(Number(seek.value));
      const now = performance.now();
      if (!this.lastSeek || now - this.lastSeek > 120) { this.lastSeek = now; this.conn.send({ type: 'replay', action: 'seek', t: Number(seek.value) }); }
    };
    seek.onchange = () => { this.seeking = false; this.conn.send({ type: 'replay', action: 'seek', t: Number(seek.value) }); };
    $('rp-rate').onchange = (e) => this.conn.send({ type: 'replay', action: 'rate', rate: Number(e.target.value) });
    $('rp-live').onclick = () => { this.conn.send({ type: 'live' }); this.panel.log('back to the live swarm'); };
    this.enable();
  }

  send(cmd, args, what) {
    try {
      const id = this.conn.command(cmd, args);
      this.panel.log(`#${id} → ${what}`);
      if (cmd === 'follow') this.setFollowing(true);
      else if (cmd !== 'teleop' && cmd !== 'distance') this.setFollowing(false);
      return id;
    } catch (e) {
      this.panel.log(e.message, 'bad');
      return null;
    }
  }

  setFollowing(on) {
    this.following = on;
    $('c-follow').classList.toggle('active', on);
    if (!on) this.keys.clear();
  }

  onAck(ack) {
    this.lastAck = ack;
    const sent = this.conn.sentCommands.get(ack.id);
    this.conn.sentCommands.delete(ack.id);
    const name = sent ? sent.cmd : 'command';
    if (name === 'teleop' && ack.ok) return;  // one per key change: not worth a log line
    this.panel.log(`#${ack.id} ${ack.ok ? '✓' : '✗'} ${ack.message ?? name}`, ack.ok ? 'ok' : 'bad');
    if (name === 'follow') this.setFollowing(!!ack.ok);
  }

  key(e, down) {
    const tag = e.target?.tagName;
    if (tag === 'INPUT' && e.target.type !== 'range' && e.target.type !== 'checkbox') return;
    if (tag === 'SELECT' || tag === 'TEXTAREA') return;
    const k = e.key?.toLowerCase();
    if (!(k in KEYS)) return;
    if (!this.following || this.source !== 'live') return;
    e.preventDefault();
    if (down) this.keys.add(k); else this.keys.delete(k);
    this.teleop();
  }

  teleop() {
    if (!this.following) return;
    const s = num('i-tspeed');
    const v = [0, 0, 0];
    for (const k of this.keys) for (let i = 0; i < 3; i++) v[i] += KEYS[k][i];
    for (let i = 0; i < 3; i++) v[i] = Math.max(-1, Math.min(1, v[i]));
    const h = Math.hypot(v[0], v[1]) || 1;  // diagonals at the set speed, not 1.4 times it
    v[0] = (v[0] / h) * s; v[1] = (v[1] / h) * s; v[2] *= s;
    if (v.every((x, i) => x === this.lastTeleop[i])) return;
    this.lastTeleop = v;
    this.send('teleop', { v }, `teleop (${v.map((x) => x.toFixed(1)).join(', ')}) m/s`);
  }

  // Live controls are off while disconnected or playing a recording.
  enable() {
    const on = this.conn.open && this.source === 'live';
    for (const b of document.querySelectorAll('#cmds button, #cmds input')) b.disabled = !on;
    $('teleop-hint').style.opacity = on ? 1 : 0.5;
  }

  setSource(source) {
    this.source = source;
    if (source !== 'live') this.setFollowing(false);
    $('replay-bar').hidden = source !== 'replay';
    this.enable();
  }

  async upload(file) {
    const st = $('rec-state');
    st.textContent = `uploading ${file.name} (${(file.size / 1e6).toFixed(1)} MB)…`;
    this.panel.log(`opening recording ${file.name}`);
    try {
      const res = await fetch(`/api/recording?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: file, headers: { 'Content-Type': 'application/octet-stream' } });
      let body = null;
      try { body = await res.json(); } catch { /* not JSON */ }
      if (!res.ok || !body?.id) throw new Error(body?.error ?? `HTTP ${res.status}`);
      st.textContent = `${body.name ?? file.name}: ${Number(body.duration ?? 0).toFixed(1)} s, ${body.frames ?? '?'} frames`;
      this.panel.log(`recording ${body.name ?? file.name}: ${Number(body.duration ?? 0).toFixed(1)} s of sim time, ${body.frames ?? '?'} frames`, 'ok');
      this.conn.send({ type: 'open', recording: body.id });
      return body;
    } catch (e) {
      st.textContent = `cannot open: ${e.message}`;
      this.panel.log(`cannot open ${file.name}: ${e.message}`, 'bad');
      return null;
    }
  }

  onReplay(r) {
    this.replay = r;
    const seek = $('rp-seek');
    const start = Number(r.start) || 0, end = start + (Number(r.duration) || 0);
    seek.min = String(start);
    seek.max = String(Math.max(end, start + 0.01));
    if (!this.seeking && Number.isFinite(r.t)) seek.value = String(r.t);
    $('rp-play').textContent = r.playing ? '❚❚' : '▶';
    const rate = $('rp-rate');
    if (Number.isFinite(r.rate) && document.activeElement !== rate) {
      const v = String(r.rate);
      if (![...rate.options].some((o) => o.value === v)) rate.add(new Option(`×${v}`, v));
      rate.value = v;
    }
    if (!this.seeking) this.showReplayTime(r.t);
  }

  showReplayTime(t) {
    const r = this.replay;
    if (!r) return;
    const start = Number(r.start) || 0;
    $('rp-time').textContent = `${(t - start).toFixed(1)} / ${(Number(r.duration) || 0).toFixed(1)} s`;
  }
}
