#include "agent/agent_cli.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <memory>

#include "agent/rejoin_policy.hpp"
#include "common/agent_rejoin.hpp"
#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/id_ranges.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

namespace ddswarm::agent {

void AgentCommandLine::add_to(CLI::App& app) {
  auto* id_opt = app.add_option("--id", id, "drone id to fly");
  app.add_option("--ids", ids_text,
                 "agent host: fly these drones in this process, e.g. 0-511 or 3-5,7")
      ->excludes(id_opt);
  app.add_option("--config,config", config, "scenario YAML (its agent: section)")->required();
  app.add_option("--duration", duration_s, "stop after this many wall seconds (0 = until Ctrl-C)")
      ->check(finite_range(0.0, 1e9));
  app.add_option("--drones", drones, "override scenario.drones");
  app.add_option("--duplicate-probe", duplicate_probe_s,
                 "s to listen for another agent flying the same drone before flying (0 = trust the "
                 "launcher)")
      ->check(finite_range(0.0, 60.0));
  app.add_flag("--check", check,
               "check the scenario as this agent would read it (drone 0 without --id), print one "
               "line and exit (0: valid, 2: the error); no DDS");
  add_dds_options(app, dds);
}

AgentAppConfig AgentCommandLine::config_for(const CLI::App& app) const {
  auto cfg = load_agent_config(config);
  if (drones) cfg.scenario.drones = *drones;
  if (id) {
    if (*id < 0 || *id >= cfg.scenario.drones)
      throw ConfigError(config + ": --id = " + std::to_string(*id) + ": must be in [0, " +
                        std::to_string(cfg.scenario.drones - 1) +
                        "] (scenario.drones = " + std::to_string(cfg.scenario.drones) + ")");
    cfg.drone_ids = {*id};
  } else {
    try {
      cfg.drone_ids = parse_id_ranges(ids_text, cfg.scenario.drones);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(config + ": " + e.what() +
                        " (scenario.drones = " + std::to_string(cfg.scenario.drones) + ")");
    }
  }
  cfg.duplicate_probe_s = duplicate_probe_s;
  merge_cli(cfg.dds, dds, app);
  default_security_role(cfg.dds, cfg.drone_ids.size() == 1
                                     ? "agent-" + std::to_string(cfg.drone_ids[0])
                                     : "agent-host");
  validate_with_overrides(config, [&] { cfg.validate(); });
  return cfg;
}

int run_agent(const AgentAppConfig& cfg, double duration_s, int argc, char** argv) {
  spdlog::set_pattern("[%H:%M:%S.%e] [%l] %v");
  install_stop_signals();
  install_rejoin_signal();
  // A killed server's lock met on a Fast DDS thread would end this agent
  // (docs/faults.md); it starts again instead and catches up with its mission.
  restart_on_dead_owner_lock("ddswarm-agent", argc, argv);
  if (const int n = restarts_in_a_row(); n > 0)
    spdlog::warn(
        "ddswarm-agent: started again ({} in a row; the line before says why); joining DDS as a "
        "new participant and catching up with the mission",
        n);
  try {
    // A new participant each time no scene came (agent.rejoin_after_s), SIGUSR1 asked for one,
    // this process outlived its DDS lease (stopped or starved), the server did not hear it or
    // it did not hear the server, or a secure server's handshake did not end
    // (agent.handshake_timeout_s). RejoinPolicy sets each join's waits and, once this
    // agent was cut off, leaves the shared-memory transport out (docs/faults.md).
    const int drones = cfg.scenario.drones;
    RejoinPolicy policy(rejoin_after_for(cfg.agent.rejoin_after_s, drones, cfg.dds.secure()),
                        cfg.dds.lease_duration_s,
                        cfg.dds.shared_memory && cfg.dds.shm_transport && !cfg.dds.secure(),
                        handshake_timeout_for(cfg.agent.handshake_timeout_s, drones));
    if (restarts_in_a_row() > 0) policy.started_again();
    keep_joining(duration_s, [&](double left) {
      auto join = cfg;  // the user's configuration stays as given
      join.agent.rejoin_after_s = policy.scene_wait_s();
      join.agent.handshake_timeout_s = policy.handshake_wait_s();
      if (!policy.shm_transport()) join.dds.shm_transport = false;
      // Fast DDS 2.9 can deadlock this thread as it makes the participant's
      // readers; the process then starts again (StuckGuard).
      auto made = [&] {
        const StuckGuard stuck("joining DDS", kDdsStepStuckS + join.duplicate_probe_s);
        return std::make_unique<AgentApp>(join);
      }();
      AgentApp& agent = *made;
      const auto end = agent.run(left);
      const bool cut_off = end == AgentApp::End::kUnheard || end == AgentApp::End::kDeaf;
      if (policy.ended(cut_off, end == AgentApp::End::kNoScene, agent.heard_scene(),
                       end == AgentApp::End::kHandshakeStall))
        spdlog::warn(
            "ddswarm-agent: joining again without the shared-memory transport (UDP "
            "on 127.0.0.1; the swarm state still by data-sharing): the server may "
            "listen on shared-memory ports no new sender reaches (docs/dds.md)");
      return end != AgentApp::End::kStopped;
    });
  } catch (const DuplicateAgent& e) {
    std::fprintf(stderr, "ddswarm-agent: error: %s\n", e.what());
    return 3;
  }
  return 0;
}

}  // namespace ddswarm::agent
