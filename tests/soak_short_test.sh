#!/usr/bin/env bash
# The chaos soak's short form (bench/soak.sh --quick): a six-drone real-time
# swarm with the recorder on meets each fault once (an agent killed and
# restarted, an agent stopped past its lease, the server killed and
# restarted, a ground station killed mid-command, the recorder killed and
# restarted, malformed and forged samples); each must be recovered from,
# no process or shared-memory file left, every recording readable and whole,
# the swarm flying at the end. The long form is a benchmark (docs/faults.md).
source "$(dirname "$0")/lib.sh"
DDSWARM_DOMAIN="$DOMAIN" timeout "$(slow 300)" bash "$SRC/bench/soak.sh" --quick --bin "$BIN" \
  --out "$WORK/soak" >"$WORK/soak.log" 2>&1
rc=$?
cat "$WORK/soak.log"
[ $rc -eq 0 ] || fail "the soak failed (exit $rc)"
grep -q "^| server_kill | 1 | 1 |" "$WORK/soak.log" || fail "the server's restart was not recovered from"
echo PASS
