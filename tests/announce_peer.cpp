// One participant for the multi-process tests: writes and reads agent
// heartbeats for --time s, then prints the most readers and writers it had
// matched at once. --tools-only announces it as an agent does under DDS Security
// (DdsConfig::announce_to_tools_only; tests/agents_never_meet_test.sh);
// --meets-no-agent as a ground station does there (DdsConfig::meets_agents); --name
// names it, e.g. as the server it is not (tests/deaf_to_new_server_test.sh).
// Localhost discovery over UDP only.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>

#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("announce_peer", [&]() -> int {
    bool meets_no_agent = false;
    CLI::App app{"a participant that counts whom it matched"};
    DdsConfig dds;
    dds.shared_memory =
        false;  // unicast pings are all the discovery there is, as under DDS Security
    double time_s = 5;
    std::string name = "announce_peer";
    app.add_option("--domain", dds.domain_id);
    app.add_option("--participant-id", dds.participant_id);
    app.add_flag("--tools-only", dds.announce_to_tools_only);
    app.add_flag("--meets-no-agent", meets_no_agent);
    app.add_option("--time", time_s);
    app.add_option("--name", name, "the participant's name");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();
    dds.meets_agents = !meets_no_agent;
    Participant p(dds, name);
    if (meets_no_agent && p.meets_agents()) throw DdsError("no participant id above the agents'");
    auto w = p.writer<msg::AgentStatus>();
    auto& r = p.reader<msg::AgentStatus>([](const msg::AgentStatus&, const fdds::SampleInfo&) {});
    int readers = 0, writers = 0;
    const double end = wall_seconds() + time_s;
    while (wall_seconds() < end && !wait_for_stop(std::chrono::milliseconds(100))) {
      readers = std::max(readers, w.matched());
      writers = std::max(writers, r.matched());
    }
    std::printf("matched readers=%d writers=%d\n", readers, writers);
    p.close();
    return 0;
  });
}
