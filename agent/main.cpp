// ddswarm-agent: the brain of one drone, a process of its own; or, with
// --ids, an agent host flying many drones' independent brains in one process.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "agent/agent_app.hpp"
#include "agent/rejoin_policy.hpp"
#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/id_ranges.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-agent", [&] {
    CLI::App app{"ddswarm-agent: flies one drone by repulsion-attraction and obstacle avoidance"};
    std::string config;
    std::optional<int> id;
    std::string ids_text;
    double duration_s = 0;
    std::optional<int> drones;
    ddswarm::DdsConfig dds_cli;
    auto* id_opt = app.add_option("--id", id, "drone id to fly");
    app.add_option("--ids", ids_text, "agent host: fly these drones in this process, e.g. 0-511 or 3-5,7")
        ->excludes(id_opt);
    app.add_option("--config,config", config, "scenario YAML (its agent: section)")->required();
    app.add_option("--duration", duration_s, "stop after this many wall seconds (0 = until Ctrl-C)")
        ->check(ddswarm::finite_range(0.0, 1e9));
    app.add_option("--drones", drones, "override scenario.drones");
    double probe_s = 1.0;
    app.add_option("--duplicate-probe", probe_s,
                   "s to listen for another agent flying the same drone before flying (0 = trust the launcher)")
        ->check(ddswarm::finite_range(0.0, 60.0));
    bool check = false;
    app.add_flag("--check", check,
                 "check the scenario as this agent would read it (drone 0 without --id), print one "
                 "line and exit (0: valid, 2: the error); no DDS");
    ddswarm::add_dds_options(app, dds_cli);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    if (check && !id && ids_text.empty()) id = 0;
    if (!id && ids_text.empty()) {
      std::fprintf(stderr, "ddswarm-agent: error: --id or --ids is required\n");
      return 2;
    }
    auto cfg = ddswarm::agent::load_agent_config(config);
    if (drones) cfg.scenario.drones = *drones;
    if (id) {
      if (*id < 0 || *id >= cfg.scenario.drones)
        throw ddswarm::ConfigError(config + ": --id = " + std::to_string(*id) + ": must be in [0, " +
                                   std::to_string(cfg.scenario.drones - 1) + "] (scenario.drones = " +
                                   std::to_string(cfg.scenario.drones) + ")");
      cfg.drone_ids = {*id};
    } else {
      try {
        cfg.drone_ids = ddswarm::parse_id_ranges(ids_text, cfg.scenario.drones);
      } catch (const std::invalid_argument& e) {
        throw ddswarm::ConfigError(config + ": " + e.what() + " (scenario.drones = " +
                                   std::to_string(cfg.scenario.drones) + ")");
      }
    }
    cfg.duplicate_probe_s = probe_s;
    ddswarm::merge_cli(cfg.dds, dds_cli, app);
    ddswarm::default_security_role(
        cfg.dds, cfg.drone_ids.size() == 1 ? "agent-" + std::to_string(cfg.drone_ids[0]) : "agent-host");
    ddswarm::validate_with_overrides(config, [&] { cfg.validate(); });
    if (check) {
      std::printf("ddswarm-agent: %s: the agent's sections are valid\n", config.c_str());
      return 0;
    }
    spdlog::set_pattern("[%H:%M:%S.%e] [%l] %v");
    ddswarm::install_stop_signals();
    ddswarm::install_rejoin_signal();
    // A killed server's lock met on a Fast DDS thread would end this agent
    // (docs/faults.md); it starts again instead and catches up with its mission.
    ddswarm::restart_on_dead_owner_lock("ddswarm-agent", argc, argv);
    if (const int n = ddswarm::dead_owner_lock_restarts(); n > 0)
      spdlog::warn("ddswarm-agent: started again after a dead peer's shared-memory lock ({} in a "
                   "row); joining DDS as a new participant and catching up with the mission",
                   n);
    try {
      using ddswarm::agent::AgentApp;
      // A new participant each time no scene came (agent.rejoin_after_s), SIGUSR1 asked for one,
      // this process outlived its DDS lease (stopped or starved), the server did not hear it or
      // it did not hear the server, or a secure server's handshake did not end
      // (agent.handshake_timeout_s). RejoinPolicy sets each join's waits and, once this
      // agent was cut off, leaves the shared-memory transport out (docs/faults.md).
      ddswarm::agent::RejoinPolicy policy(
          cfg.agent.rejoin_after_s, cfg.dds.lease_duration_s,
          cfg.dds.shared_memory && cfg.dds.shm_transport && !cfg.dds.secure(),
          cfg.agent.handshake_timeout_s);
      ddswarm::keep_joining(duration_s, [&](double left) {
        auto join = cfg;  // the user's configuration stays as given
        join.agent.rejoin_after_s = policy.scene_wait_s();
        join.agent.handshake_timeout_s = policy.handshake_wait_s();
        if (!policy.shm_transport()) join.dds.shm_transport = false;
        AgentApp agent(join);
        const auto end = agent.run(left);
        const bool cut_off = end == AgentApp::End::kUnheard || end == AgentApp::End::kDeaf;
        if (policy.ended(cut_off, end == AgentApp::End::kNoScene, agent.heard_scene(),
                         end == AgentApp::End::kHandshakeStall))
          spdlog::warn("ddswarm-agent: joining again without the shared-memory transport (UDP "
                       "on 127.0.0.1; the swarm state still by data-sharing): the server may "
                       "listen on shared-memory ports no new sender reaches (docs/dds.md)");
        return end != AgentApp::End::kStopped;
      });
    } catch (const ddswarm::agent::DuplicateAgent& e) {
      std::fprintf(stderr, "ddswarm-agent: error: %s\n", e.what());
      return 3;
    }
    return 0;
  });
  return ddswarm::end_process(code);
}
