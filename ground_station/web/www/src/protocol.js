// Protocol v1 between the page and the bridge (docs/web_view.md): constants
// and small pure helpers, shared with dev/mock_bridge.mjs. No three.js here.

export const PROTOCOL_VERSION = 1;

// Bits of DroneState.flags (idl/DroneState.idl).
export const FLAG = Object.freeze({
  AIRBORNE: 1,
  FAILSAFE: 2,
  AGENT_LIVE: 4,
  OUT_OF_BOUNDS: 8,
  PAST_FINISH: 16,
  MOTORS_ON: 32,
});

// common/mission.hpp Phase, in order.
export const PHASES = Object.freeze(['idle', 'takeoff', 'hold', 'move', 'task', 'swarm', 'follow', 'landing', 'failsafe']);

export function phaseName(p) {
  if (typeof p === 'string') return p;
  return PHASES[p] ?? `phase ${p}`;
}

// Short flag words for the drone table, most important first.
export function flagWords(flags) {
  const w = [];
  if (!(flags & FLAG.AGENT_LIVE)) w.push('LOST');
  if (flags & FLAG.FAILSAFE) w.push('FAILSAFE');
  if (flags & FLAG.OUT_OF_BOUNDS) w.push('OUT');
  if (flags & FLAG.AIRBORNE) w.push('air');
  if (flags & FLAG.PAST_FINISH) w.push('fin');
  return w.join(' ');
}

// Marking of a drone: 'lost' (its agent is not heard), 'failsafe', or ''.
// A drone in a replay or before the first agent heartbeat has no AGENT_LIVE
// bit either, so the caller decides whether 'lost' applies (see main.js).
export function markOf(flags) {
  if (flags & FLAG.FAILSAFE) return 'failsafe';
  if (!(flags & FLAG.AGENT_LIVE)) return 'lost';
  return '';
}

export const norm3 = (v) => Math.hypot(v[0], v[1], v[2]);

// The commands the page sends, with their argument checks (the bridge checks
// again; these only keep obviously bad input off the wire).
export const COMMANDS = Object.freeze({
  takeoff: ['altitude'],
  move: ['v', 'duration'],
  distance: ['value'],
  land: [],
  hold: [],
  task: ['speed', 'epsilon'],
  follow: ['leader'],
  teleop: ['v'],
});

export function checkCommand(cmd, args) {
  const fields = COMMANDS[cmd];
  if (!fields) return `unknown command "${cmd}"`;
  for (const f of fields) {
    const x = args[f];
    const bad = Array.isArray(x) ? x.length !== 3 || !x.every(Number.isFinite) : !Number.isFinite(x);
    if (bad) return `${cmd}: ${f} must be ${f === 'v' ? 'three finite numbers' : 'a finite number'} (got ${JSON.stringify(x)})`;
  }
  if (cmd === 'takeoff' && args.altitude < 0) return `takeoff: altitude must be >= 0 m (0: the agents' default; got ${args.altitude})`;
  if (cmd === 'move' && args.duration <= 0) return `move: duration must be > 0 s (got ${args.duration})`;
  if (cmd === 'distance' && args.value <= 0.3) return `distance: value must be > 0.3 m (got ${args.value})`;
  if (cmd === 'task' && args.speed <= 0) return `task: speed must be > 0 m/s (got ${args.speed})`;
  if (cmd === 'follow' && (!Number.isInteger(args.leader) || args.leader < 0)) return `follow: leader must be a drone id (got ${args.leader})`;
  return null;
}

// Formats seconds as m:ss.s (or s.s below a minute).
export function fmtDuration(s) {
  if (!Number.isFinite(s)) return '–';
  const neg = s < 0; s = Math.abs(s);
  const m = Math.floor(s / 60), r = s - 60 * m;
  const out = m > 0 ? `${m}:${r.toFixed(1).padStart(4, '0')}` : `${r.toFixed(1)} s`;
  return neg ? `-${out}` : out;
}
