# Shared by the bench scripts (source it after setting SRC).

# A random DDS domain whose RTPS ports stay below the kernel's ephemeral port
# range for the explicit participant ids of a 128-agent swarm (ids up to 159;
# see ddswarm-launch's ephemeral-port warning and docs/networking.md).
bench_domain() { echo $(( (RANDOM % 60) + 20 )); }

# bench_scenario FILE: writes the thesis course with ground-station timeouts
# that a loaded machine and a 128-process bring-up can meet, and the law for
# dense swarms (agent.activation.neighbours: 6): the thesis's sum over every
# peer packs 16 and more drones until they touch, and the contacts, not the
# swarm, would dominate the server's cost. With 7 drones or fewer the two
# laws are the same. --set agent.activation.neighbours=0 flies the thesis's.
bench_scenario() {
  sed -e 's/^  ack_timeout_s: .*/  ack_timeout_s: 30.0\n  discovery_timeout_s: 60.0/' \
    -e 's/^\(    max_mps: 1.5\)$/\1\n    neighbours: 6/' \
    "$SRC/config/thesis_course.yaml" >"$1"
  grep -q "discovery_timeout_s: 60.0" "$1" && grep -q "^    neighbours: 6$" "$1" ||
    { echo "$(basename "$0"): cannot derive $1" >&2; exit 2; }
}
