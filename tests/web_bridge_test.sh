#!/usr/bin/env bash
# `ddswarm-gs --web` streams the live swarm to a WebSocket client
# (tests/web_client.cpp stands in for the browser): hello, scene and frames
# with every drone; a takeoff command acknowledged and seen airborne in the
# frames and in the DDS state; malformed messages answered with `error` while
# frames keep coming; a client dropped mid-stream does not stop the bridge; an
# uploaded MCAP recording plays, seeks and pauses; SIGTERM exits 0.
source "$(dirname "$0")/lib.sh"
scenario="$SRC/config/thesis_course.yaml"
gs() { timeout 60 "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" "$@"; }
wc_() { WEB_CLIENT_TIMEOUT=60 "$BIN/web_client" "$@"; }

# Bad addresses: one line, exit 2, nothing served.
for bad in nonsense 127.0.0.1:99999 0.0.0.0:0; do
  out=$("$BIN/ddswarm-gs" --domain "$DOMAIN" --web "$bad" 2>&1); rc=$?
  [ $rc -eq 2 ] || fail "--web $bad exited $rc: $out"
  [ "$(echo "$out" | wc -l)" -eq 1 ] && echo "$out" | grep -q -- "--web" || fail "--web $bad: unclear error: $out"
done

start launch "$BIN/ddswarm-launch" "$scenario" --drones 4 --mode realtime --domain "$DOMAIN" --log-dir "$WORK/logs"
start web "$BIN/ddswarm-gs" --config "$scenario" --domain "$DOMAIN" --web 127.0.0.1:0
port=""
for _ in $(seq 100); do
  port=$(sed -n 's|^web: serving http://127.0.0.1:\([0-9]*\)/$|\1|p' "$WORK/web.log")
  [ -n "$port" ] && break; sleep 0.1
done
[ -n "$port" ] || fail "the bridge printed no URL"
echo "bridge on port $port"
gs wait-agents --count 4 --timeout 60 || fail "agents not online"

# Static files: the page, and no way out of the web root.
wc_ get "$port" / | grep -q "^200 text/html" || fail "GET / is not the page"
wc_ get "$port" "/../../../../etc/passwd" | grep -q "^404" || fail "path traversal not refused"
wc_ get "$port" "/%2e%2e/%2e%2e/etc/passwd" | grep -q "^404" || fail "encoded path traversal not refused"

# Record the swarm while it takes off, for the replay below.
start rec "$BIN/ddswarm-record" -o "$WORK/run.mcap" --domain "$DOMAIN" \
  --topics ddswarm/swarm_state,ddswarm/scene,ddswarm/status,ddswarm/task,ddswarm/collision
sleep 1

# One client: live view, takeoff through the page's command, malformed input,
# then it vanishes mid-stream without a close frame.
wc_ ws "$port" type=hello type=scene drones=4 'send={"type":"subscribe","fps":20,"rays":true}' \
  'send={"type":"command","id":1,"cmd":"takeoff"}' ack=1:ok airborne=4 \
  'send=this is not json' 'error=not JSON' frames=3 \
  'send={"type":"command","id":2,"cmd":"takeoff","altitude":-5}' 'error=command.altitude = -5' frames=3 \
  'send={"type":"warp"}' 'error=type = "warp": unknown' \
  'send={"type":"command","id":3,"cmd":"move","v":[1,0,0],"duration":1e999}' 'error=number overflow' \
  binary 'error=binary frame' big=70000 'error=over the 64 KiB limit' \
  frames=10 type=status abort >"$WORK/client1.out" 2>&1 || { cat "$WORK/client1.out"; fail "first client"; }
cat "$WORK/client1.out"
# The DDS truth agrees: the swarm is airborne, and no malformed message reached the swarm.
out=$(gs status) || fail "status: $out"
echo "$out"
echo "$out" | grep -q "| 4 airborne |" || fail "DDS status does not show 4 drones airborne: $out"

# The bridge keeps serving a new client after that abrupt disconnect.
wc_ ws "$port" type=hello drones=4 frames=20 airborne=4 close >"$WORK/client2.out" 2>&1 || { cat "$WORK/client2.out"; fail "second client after the abrupt disconnect"; }
cat "$WORK/client2.out"

# Replay: upload the recording, open it, seek, pause, go live again.
kill -INT "$PID_rec"; wait_pid "$PID_rec" 15 || fail "recorder did not stop"
wc_ upload "$port" "$WORK/run.mcap" run.mcap >"$WORK/upload.json" || { cat "$WORK/upload.json"; fail "upload refused"; }
cat "$WORK/upload.json"
id=$(sed -n 's/.*"id":"\([^"]*\)".*/\1/p' "$WORK/upload.json")
start_t=$(sed -n 's/.*"start":\([0-9.e+-]*\).*/\1/p' "$WORK/upload.json")
[ -n "$id" ] && [ -n "$start_t" ] || fail "upload answer lacks id/start"
mid=$(awk -v s="$start_t" 'BEGIN { printf "%.3f", s + 1.0 }')
wc_ ws "$port" type=hello "send={\"type\":\"open\",\"recording\":\"$id\"}" type=hello type=scene replay=playing:true \
  drones=4 'send={"type":"replay","action":"pause"}' replay=playing:false \
  "send={\"type\":\"replay\",\"action\":\"seek\",\"t\":$mid}" "replay-t=$(awk -v m="$mid" 'BEGIN{print m-0.05}'):$(awk -v m="$mid" 'BEGIN{print m+0.05}')" \
  'send={"type":"replay","action":"rate","rate":4}' 'send={"type":"replay","action":"play"}' replay=rate:4.0 \
  'send={"type":"command","id":9,"cmd":"land"}' ack=9:fail \
  'send={"type":"open","recording":"nope"}' 'error=no such recording' \
  'send={"type":"live"}' type=hello drones=4 close >"$WORK/client3.out" 2>&1 || { cat "$WORK/client3.out"; fail "replay client"; }
cat "$WORK/client3.out"
# A file that is not MCAP is a clear HTTP 400.
head -c 5000 /dev/urandom >"$WORK/junk.mcap"
out=$(wc_ upload "$port" "$WORK/junk.mcap" junk.mcap); rc=$?
[ $rc -ne 0 ] && echo "$out" | grep -q '"error"' || fail "junk upload: rc $rc: $out"
echo "junk upload: $out"
# Uploads over Beast's default 1 MiB body limit reach our own checks (a 3 MB
# non-MCAP is read whole and refused as such, not dropped mid-upload).
head -c 3000000 /dev/urandom >"$WORK/big.mcap"
out=$(wc_ upload "$port" "$WORK/big.mcap" big.mcap); rc=$?
echo "$out" | grep -q '"error"' && ! echo "$out" | grep -q "limit" || fail "3 MB upload: rc $rc: $out"

# Land through the page, then stop the bridge: SIGTERM, exit 0, counts in its last line.
wc_ ws "$port" type=hello 'send={"type":"command","id":4,"cmd":"land"}' ack=4:ok close >/dev/null || fail "land"
kill -TERM "$PID_web"; wait_pid "$PID_web" 10; rc=$?
[ $rc -eq 0 ] || fail "the bridge exited $rc on SIGTERM"
tail -1 "$WORK/web.log"
grep -Eq "web: 4 client\(s\), [0-9]+ frames sent.*, ([7-9]|[1-9][0-9]+) malformed messages.*, 2 commands, 1 recordings" "$WORK/web.log" \
  || fail "bridge counts unexpected: $(tail -1 "$WORK/web.log")"
echo PASS
