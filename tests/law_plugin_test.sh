#!/usr/bin/env bash
# A swarm law built out of ddswarm's tree (examples/law_plugin), as a user's
# own repository builds it: against the installed CMake package
# (cmake --install, find_package(ddswarm)). Then, in lockstep:
# 1. the whole swarm flies the plug-in's spring law through the thesis task;
# 2. a plug-in that crashes its process (SIGSEGV, drone 4) takes down that
#    agent alone: the server's failsafe lands its drone and the five others
#    complete the task;
# 3. a library that is no plug-in, or one built against another law API
#    version, is refused before anything flies: one line, exit 2.
source "$(dirname "$0")/lib.sh"
LAUNCH_AGENT_TIMEOUT_S=2
scenario="$SRC/config/thesis_course.yaml"
build_dir="$(dirname "$BIN")"
cmake --install "$build_dir" --prefix "$WORK/prefix" >"$WORK/install.log" 2>&1 || { cat "$WORK/install.log"; fail "cmake --install"; }
[ -f "$WORK/prefix/include/ddswarm/law.hpp" ] || fail "the law header was not installed"
cmake -S "$SRC/examples/law_plugin" -B "$WORK/my_law" -DCMAKE_PREFIX_PATH="$WORK/prefix" \
  -DCMAKE_BUILD_TYPE=Release >"$WORK/configure.log" 2>&1 || { cat "$WORK/configure.log"; fail "the example did not configure"; }
cmake --build "$WORK/my_law" -j 2 >"$WORK/build.log" 2>&1 || { cat "$WORK/build.log"; fail "the example did not build"; }
spring="$WORK/my_law/libspring_law.so"
crash="$WORK/my_law/libcrash_law.so"
[ -f "$spring" ] && [ -f "$crash" ] || fail "the example built no plug-in"


launch_lockstep spring --set agent.law.type=plugin --set agent.law.library="$spring" \
  --gs 'takeoff --wait; status; task --speed 0.8' || fail "the plug-in swarm's launch failed"
grep -q "task complete:" "$WORK/spring.log" || fail "the plug-in swarm did not complete the task"
grep -q "| law plugin libspring_law.so" "$WORK/spring.log" || fail "the status line does not name the plug-in"
grep -q "flying the plugin libspring_law.so law" "$WORK/spring/agent_0.log" || fail "agent 0 does not say it flies the plug-in"

launch_lockstep crash --on-death keep \
  --set "agent.overrides=[{ids: 4, law: {type: plugin, library: \"$crash\", params: {crash_after_s: 15}}}]" \
  --gs 'takeoff --wait; task --speed 0.8' || fail "the launch with a crashing plug-in failed"
grep -q "task complete:" "$WORK/crash.log" || fail "the five sound drones did not complete the task"
grep -q "lost drones (agent lost, failsafe): 4" "$WORK/crash.log" || fail "drone 4 is not reported lost"
grep -q "agent 4 (pid [0-9]*) was killed by SIGSEGV" "$WORK/crash.log" ||
  fail "the launcher did not report agent 4's crash"
for id in 0 1 2 3 5; do
  grep -qi "segmentation\|error" "$WORK/crash/agent_$id.log" && fail "agent $id logged an error"
done

# Refused before anything starts: a library that is no plug-in, and an old API.
cat >"$WORK/old_api.cpp" <<'CPP'
extern "C" int ddswarm_law_api_version() { return 0; }
extern "C" void* ddswarm_law_factory() { return nullptr; }
CPP
c++ -shared -fPIC -o "$WORK/libold_api.so" "$WORK/old_api.cpp" || fail "could not build the old-API library"
refused_law "{type: plugin, library: $WORK/libold_api.so}" \
  "refused.yaml:64: agent.law.library = $WORK/libold_api.so: was built against law API version 0, this ddswarm has version 1"
refused_law "{type: plugin, library: /lib/x86_64-linux-gnu/libm.so.6}" "is not a ddswarm law plug-in"
refused_law "{type: plugin, library: $WORK/missing.so}" "agent.law.library = $WORK/missing.so: no such file"
echo PASS
