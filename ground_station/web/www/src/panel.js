// The side panel: connection, sim clock, task, the drone table and the log.
// The table is rebuilt only when the number of drones changes and its cells
// are refreshed a few times a second, only where their text changed.
import { FLAG, phaseName, flagWords, fmtDuration, norm3 } from './protocol.js';

const $ = (id) => document.getElementById(id);

function setText(el, text) {
  if (el.textContent !== text) el.textContent = text;
}

// "3.0 m/s toward 90° (east) · turbulence σ 0.6/0.6/0.3 m/s · gusts 2/min ≤ 3 m/s", or "calm".
export function windText(w) {
  if (!w) return '–';
  const [x, y, z] = w.steady ?? [0, 0, 0];
  const speed = Math.hypot(x, y, z);
  const parts = [];
  if (speed > 0) {
    const bearing = ((Math.atan2(x, y) * 180) / Math.PI + 360) % 360;  // from north, clockwise
    parts.push(`${speed.toFixed(1)} m/s toward ${bearing.toFixed(0)}°`);
  }
  if (w.turbulence) parts.push(`turbulence σ ${(w.sigma ?? []).map((v) => v.toFixed(2)).join('/')} m/s`);
  if (w.gusts_per_minute > 0) parts.push(`gusts ${w.gusts_per_minute}/min ≤ ${w.gust_max} m/s`);
  return parts.length ? parts.join(' · ') : 'calm';
}

export class Panel {
  constructor({ onSelect } = {}) {
    this.el = {
      conn: $('conn'), source: $('source'), scene: $('s-scene'), time: $('s-time'), rtf: $('s-rtf'),
      state: $('s-state'), agents: $('s-agents'), air: $('s-air'), coll: $('s-coll'),
      task: $('s-task'), wind: $('s-wind'), timer: $('s-timer'), body: $('d-body'), count: $('d-count'), log: $('log'),
    };
    this.rows = [];
    this.onSelect = onSelect;
    this.selected = -1;
    this.task = null;
    this.taskAt = null;  // sim time at which the task message arrived
    this.hit = new Map();  // drone id -> until (ms)
  }

  setConnection(state) {
    const e = this.el.conn;
    e.textContent = state === 'open' ? 'connected' : state === 'connecting' ? 'connecting…' : 'disconnected';
    e.className = `badge ${state === 'open' ? 'on' : 'off'}`;
  }

  setSource(source, name) {
    const e = this.el.source;
    e.textContent = source === 'replay' ? `replay${name ? `: ${name}` : ''}` : 'live';
    e.className = `badge ${source === 'replay' ? 'replay' : ''}`;
  }

  setScene(s) {
    setText(this.el.scene, `${s.name ?? '?'} · seed ${s.seed ?? '?'} · ${s.mode ?? ''}`);
    setText(this.el.wind, windText(s.wind));
    this.buildTable(s.num_drones ?? 0);
  }

  setStatus(st) {
    setText(this.el.state, `${st.mode ?? ''}${st.state ? `, ${st.state}` : ''}`);
    setText(this.el.rtf, Number.isFinite(st.rtf) ? `×${st.rtf.toFixed(2)}` : '–');
    setText(this.el.agents, `${st.agents_live ?? '?'}/${st.num_drones ?? '?'} live`);
    setText(this.el.air, `${st.airborne ?? '?'}${st.failsafe ? ` · failsafe ${st.failsafe}` : ''}`);
    const c = st.collisions ?? [0, 0, 0];
    setText(this.el.coll, `obstacle ${c[0]} · drone ${c[1]} · ground ${c[2]}`);
  }

  setTask(task, simT) {
    this.task = task;
    this.taskAt = simT;
    const st = task.state ?? 'none';
    const parts = [task.phase && task.phase !== st ? `${st} (${task.phase})` : st];
    if (st !== 'none') {
      if (Number.isFinite(task.past_finish) && Number.isFinite(task.drones)) parts.push(`${task.past_finish}/${task.drones} past finish`);
      if (Number.isFinite(task.max_pair)) parts.push(`spread ${task.max_pair.toFixed(1)} m`);
    }
    if (st === 'failed' && task.reason) parts.push(task.reason);
    setText(this.el.task, parts.join(' · '));
  }

  // Sim time and the running task timer (the task message carries the
  // elapsed time when it changed; it runs on with the sim clock).
  setTime(t) {
    setText(this.el.time, Number.isFinite(t) ? `${t.toFixed(2)} s` : '–');
    const task = this.task;
    if (!task || task.state === 'none' || !Number.isFinite(task.elapsed)) { setText(this.el.timer, '–'); return; }
    let e = task.elapsed;
    if (task.state === 'running' && Number.isFinite(this.taskAt) && Number.isFinite(t)) e += Math.max(0, t - this.taskAt);
    setText(this.el.timer, fmtDuration(e) + (task.state === 'complete' ? ' (final)' : ''));
  }

  buildTable(n) {
    if (this.rows.length === n) return;
    const body = this.el.body;
    body.textContent = '';
    this.rows = [];
    const frag = document.createDocumentFragment();
    for (let i = 0; i < n; i++) {
      const tr = document.createElement('tr');
      tr.dataset.id = i;
      const cells = [];
      for (let k = 0; k < 6; k++) { const td = document.createElement('td'); tr.appendChild(td); cells.push(td); }
      cells[0].textContent = String(i);
      tr.addEventListener('click', () => this.select(i));
      frag.appendChild(tr);
      this.rows.push({ tr, cells, cls: '' });
    }
    body.appendChild(frag);
    setText(this.el.count, n ? `(${n})` : '');
  }

  select(i) {
    if (this.rows[this.selected]) this.rows[this.selected].tr.classList.remove('sel');
    this.selected = this.selected === i ? -1 : i;
    if (this.rows[this.selected]) this.rows[this.selected].tr.classList.add('sel');
    this.onSelect?.(this.selected);
  }

  markHit(id, nowMs) {
    this.hit.set(id, nowMs + 1500);
  }

  // Refreshes the table from the latest frame (call a few times a second):
  // only the rows in view (with a margin), as layout is what costs.
  updateTable(frame, isLost, nowMs) {
    if (!frame) return;
    const wrap = this.el.body.closest('.tablewrap');
    const rowH = this.rows[0]?.tr.offsetHeight || 20;
    const first = Math.max(0, Math.floor(wrap.scrollTop / rowH) - 5);
    const last = first + Math.ceil(wrap.clientHeight / rowH) + 10;
    const drones = frame.drones ?? [];
    for (let k = first; k <= last && k < drones.length; k++) {
      const d = drones[k];
      const row = this.rows[d?.id];
      if (!row) continue;
      const c = row.cells;
      setText(c[1], phaseName(d.phase));
      setText(c[2], Array.isArray(d.v) ? norm3(d.v).toFixed(2) : '–');
      setText(c[3], Number.isFinite(d.nearest) ? d.nearest.toFixed(2) : '–');
      const col = Array.isArray(d.col) ? d.col : [0, 0, 0];
      setText(c[4], `${col[0]}/${col[1]}/${col[2]}`);
      const lost = isLost(d.id);
      let words = flagWords(d.flags | 0);
      if (lost && !words.includes('LOST')) words = `LOST ${words}`;
      if (!lost) words = words.replace(/^LOST ?/, '');
      setText(c[5], words);
      const hit = (this.hit.get(d.id) ?? 0) > nowMs;
      const cls = `${d.flags & FLAG.FAILSAFE ? 'failsafe' : lost ? 'lost' : ''}${hit ? ' hit' : ''}${d.id === this.selected ? ' sel' : ''}`;
      if (cls !== row.cls) { row.tr.className = cls; row.cls = cls; }
    }
  }

  log(text, level = 'info') {
    const li = document.createElement('li');
    const now = new Date();
    li.textContent = `${now.toTimeString().slice(0, 8)} ${text}`;
    li.className = level;
    const log = this.el.log;
    log.appendChild(li);
    while (log.childElementCount > 200) log.firstElementChild.remove();
    log.scrollTop = log.scrollHeight;
  }
}
