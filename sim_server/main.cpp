// ddswarm-sim: the simulation server.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "sim_server/sim_cli.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-sim", [&] {
    CLI::App app{"ddswarm-sim: steps every quadrotor in Bullet and serves the swarm over DDS"};
    ddswarm::sim::SimCommandLine cli;
    cli.add_to(app);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    const auto cfg = cli.config_for(app);
    if (cli.check) {
      std::printf("ddswarm-sim: %s: the server's sections are valid\n", cli.scenario.c_str());
      return 0;
    }
    return ddswarm::sim::run_sim(cfg, cli.duration_s);
  });
  return ddswarm::end_process(code);
}
