#include "sim_server/sim_cli.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/shm_clean.hpp"

namespace ddswarm::sim {

void SimCommandLine::add_to(CLI::App& app) {
  app.add_option("--scenario,scenario", scenario, "scenario YAML")->required();
  app.add_option("--duration", duration_s,
                 "stop after this many wall seconds (0 = run until Ctrl-C)")
      ->check(finite_range(0.0, 1e9));
  app.add_option("--seed", seed, "override scenario.seed");
  app.add_option("--drones", drones, "override scenario.drones");
  app.add_option("--mode", mode, "override scenario.mode")
      ->check(CLI::IsMember({"realtime", "lockstep"}));
  app.add_flag("--check", check,
               "check the scenario as this server would read it, print one line and exit (0: "
               "valid, 2: the error); no DDS");
  add_dds_options(app, dds);
}

ServerConfig SimCommandLine::config_for(const CLI::App& app) const {
  auto cfg = load_server_config(scenario);
  if (seed) cfg.scenario.seed = *seed;
  if (drones) cfg.scenario.drones = *drones;
  if (mode) cfg.scenario.mode = *mode == "lockstep" ? TimeMode::kLockstep : TimeMode::kRealtime;
  merge_cli(cfg.dds, dds, app);
  default_security_role(cfg.dds, "server");
  validate_with_overrides(scenario, [&] { cfg.validate(); });
  return cfg;
}

int run_sim(const ServerConfig& cfg, double duration_s) {
  install_stop_signals();
  // Segments that crashed runs left in /dev/shm pile up until the next run
  // cannot map its own: clear the zombies (never a live process's) first.
  // Named, so a log tells which process's files went.
  const auto r = clean_zombie_shm();
  if (r.spared > 0)
    spdlog::info(
        "left {} unused shared-memory files younger than {} s (a starting participant's, or "
        "removed by a later start)",
        r.spared, kShmZombieMinAgeS);
  if (r.files_removed > 0)
    spdlog::info("removed {} shared-memory files ({:.1f} MB) left by crashed processes: {}",
                 r.files_removed, r.bytes_freed / 1e6, r.removed_names(6));
  install_rejoin_signal();
  std::uint64_t rival = 0;
  keep_joining(duration_s, [&](double left) {
    SimServer server(cfg);
    const auto end = server.run(left);
    rival = server.rival_instance();
    return end == SimServer::End::kRejoinRequested;
  });
  if (rival != 0) {
    std::fprintf(stderr,
                 "ddswarm-sim: error: another server (instance %016llx) is already on DDS domain "
                 "%d: two swarms on one domain would be one; use another --domain\n",
                 static_cast<unsigned long long>(rival), cfg.dds.domain_id);
    return 3;
  }
  return 0;
}

}  // namespace ddswarm::sim
