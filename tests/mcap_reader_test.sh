#!/usr/bin/env bash
# Our MCAP files, read by an independent implementation: Foxglove's own
# TypeScript library (@mcap/core, versions pinned in tests/package-lock.json).
# For each compression (zstd, lz4, none) mcap_fixture writes a known file and
# tests/mcap_independent_reader.mjs must find its 3 channels and exactly the
# expected messages per topic, with indexed and stream reads agreeing and
# every CRC (chunk, summary, data section) verified. A writer killed after 4
# chunks must leave a file whose complete chunks a stream reader reads. A
# wrong expectation must fail (the checker is not vacuous).
#
# Installs the npm packages (npm ci) when missing; exits 77 (skip) only when
# node/npm are absent. Needs DDSWARM_BIN and DDSWARM_SRC (set by ctest).
set -euo pipefail
BIN="${DDSWARM_BIN:?DDSWARM_BIN must point at the build bin directory}"
SRC="${DDSWARM_SRC:?DDSWARM_SRC must point at the source tree}"
READER="$SRC/tests/mcap_independent_reader.mjs"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "SKIP: node and npm are needed for the independent MCAP reader"
  exit 77
fi
packages_present() {  # installed, and from the current lock file
  local p
  [ "$SRC/tests/node_modules/.package-lock.json" -nt "$SRC/tests/package-lock.json" ] || return 1
  for p in @mcap/core @mcap/nodejs @foxglove/wasm-zstd @foxglove/wasm-lz4 @foxglove/crc; do
    [ -f "$SRC/tests/node_modules/$p/package.json" ] || return 1
  done
}
if ! packages_present; then
  echo "installing the independent reader's npm packages (npm ci --prefix tests)"
  npm ci --prefix "$SRC/tests" --no-audit --no-fund --loglevel=error
fi

WORK="$(mktemp -d /tmp/ddswarm-mcap.XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
passed=0
failed=0
ok() { echo "ok: $1"; passed=$((passed + 1)); }
bad() { echo "FAIL: $1"; failed=$((failed + 1)); }

# Runs the independent reader; its JSON goes to $WORK/NAME.json, shown on failure.
# Node 20 can deadlock in its own shutdown after the verdict is printed
# (nodejs/node#54918); --single-threaded makes that rare, and a reader that
# printed "ok": true and then hung is killed and counted on its verdict.
run_reader() {
  local out="$1" rc=0
  shift
  timeout -k 2 30 node --single-threaded "$READER" "$@" >"$out" 2>&1 || rc=$?
  if [ "$rc" -ge 124 ] && tail -n 3 "$out" | grep -q '"ok": true'; then
    echo "note: node hung at exit after its verdict; killed"
    rc=0
  fi
  return "$rc"
}
read_check() {
  local name="$1"
  shift
  if run_reader "$WORK/$name.json" "$@"; then
    ok "$name"
  else
    bad "$name"
    cat "$WORK/$name.json"
  fi
}
expect_args() {  # "topic=N" lines -> --expect-count topic=N ...
  local line
  for line in $(cat "$1"); do printf -- '--expect-count\n%s\n' "$line"; done
}

full_counts=$'/ddswarm/drone_state=3000\n/ddswarm/command=1000\n/ddswarm/clock=500'
for c in zstd lz4 none; do
  "$BIN/mcap_fixture" "$WORK/$c.mcap" --compression "$c" >"$WORK/$c.expect"
  if [ "$(cat "$WORK/$c.expect")" != "$full_counts" ]; then
    bad "fixture $c counts"
    cat "$WORK/$c.expect"
  fi
  mapfile -t args < <(expect_args "$WORK/$c.expect")
  read_check "$c" "$WORK/$c.mcap" --expect-channels 3 "${args[@]}"
done

# A recorder that dies: no summary, no footer; the complete chunks must read.
"$BIN/mcap_fixture" "$WORK/crash.mcap" --crash-after-chunks 4 >"$WORK/crash.expect"
mapfile -t args < <(expect_args "$WORK/crash.expect")
if [ "${#args[@]}" -ne 6 ] || grep -q '=0$' "$WORK/crash.expect"; then
  bad "crash fixture counts"
  cat "$WORK/crash.expect"
fi
read_check crash "$WORK/crash.mcap" --stream-only --expect-channels 3 "${args[@]}"
if run_reader "$WORK/crash_indexed.json" "$WORK/crash.mcap"; then
  bad "crash file must not pass as indexed"
else
  ok "crash file has no index"
fi

if run_reader "$WORK/neg.json" "$WORK/zstd.mcap" --expect-count /ddswarm/clock=499; then
  bad "a wrong expectation passed"
  cat "$WORK/neg.json"
else
  ok "wrong expectation rejected"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
