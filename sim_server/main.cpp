// ddswarm-sim: the simulation server.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/shm_clean.hpp"
#include "sim_server/sim_server.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-sim", [&] {
    CLI::App app{"ddswarm-sim: steps every quadrotor in Bullet and serves the swarm over DDS"};
    std::string scenario;
    double duration_s = 0;
    std::optional<std::uint64_t> seed;
    std::optional<int> drones;
    std::optional<std::string> mode;
    ddswarm::DdsConfig dds_cli;
    app.add_option("--scenario,scenario", scenario, "scenario YAML")->required();
    app.add_option("--duration", duration_s,
                   "stop after this many wall seconds (0 = run until Ctrl-C)")
        ->check(ddswarm::finite_range(0.0, 1e9));
    app.add_option("--seed", seed, "override scenario.seed");
    app.add_option("--drones", drones, "override scenario.drones");
    app.add_option("--mode", mode, "override scenario.mode")
        ->check(CLI::IsMember({"realtime", "lockstep"}));
    bool check = false;
    app.add_flag(
        "--check", check,
        "check the scenario as this server would read it, print one line and exit (0: valid, "
        "2: the error); no DDS");
    ddswarm::add_dds_options(app, dds_cli);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    auto cfg = ddswarm::sim::load_server_config(scenario);
    if (seed) cfg.scenario.seed = *seed;
    if (drones) cfg.scenario.drones = *drones;
    if (mode)
      cfg.scenario.mode =
          *mode == "lockstep" ? ddswarm::TimeMode::kLockstep : ddswarm::TimeMode::kRealtime;
    ddswarm::merge_cli(cfg.dds, dds_cli, app);
    ddswarm::default_security_role(cfg.dds, "server");
    ddswarm::validate_with_overrides(scenario, [&] { cfg.validate(); });
    if (check) {
      std::printf("ddswarm-sim: %s: the server's sections are valid\n", scenario.c_str());
      return 0;
    }
    ddswarm::install_stop_signals();
    // Segments that crashed runs left in /dev/shm pile up until the next run
    // cannot map its own: clear the zombies (never a live process's) first.
    // Named, so a log tells which process's files went.
    const auto r = ddswarm::clean_zombie_shm();
    if (r.spared > 0)
      spdlog::info(
          "left {} unused shared-memory files younger than {} s (a starting "
          "participant's, or removed by a later start)",
          r.spared, ddswarm::kShmZombieMinAgeS);
    if (r.files_removed > 0)
      spdlog::info("removed {} shared-memory files ({:.1f} MB) left by crashed processes: {}",
                   r.files_removed, r.bytes_freed / 1e6, r.removed_names(6));
    ddswarm::install_rejoin_signal();
    // A new server each time SIGUSR1 asks before a mission (SimServer::run).
    std::uint64_t rival = 0;
    ddswarm::keep_joining(duration_s, [&](double left) {
      ddswarm::sim::SimServer server(cfg);
      const auto end = server.run(left);
      rival = server.rival_instance();
      return end == ddswarm::sim::SimServer::End::kRejoinRequested;
    });
    if (rival != 0) {
      std::fprintf(
          stderr,
          "ddswarm-sim: error: another server (instance %016llx) is already on DDS domain %d: "
          "two swarms on one domain would be one; use another --domain\n",
          static_cast<unsigned long long>(rival), cfg.dds.domain_id);
      return 3;
    }
    return 0;
  });
  return ddswarm::end_process(code);
}
