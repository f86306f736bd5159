// ddswarm-agent: the brain of one drone, a process of its own; or, with
// --ids, an agent host flying many drones' independent brains in one process.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "agent/agent_cli.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-agent", [&] {
    CLI::App app{"ddswarm-agent: flies one drone by repulsion-attraction and obstacle avoidance"};
    ddswarm::agent::AgentCommandLine cli;
    cli.add_to(app);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    if (cli.check && !cli.id && cli.ids_text.empty()) cli.id = 0;
    if (!cli.id && cli.ids_text.empty()) {
      std::fprintf(stderr, "ddswarm-agent: error: --id or --ids is required\n");
      return 2;
    }
    const auto cfg = cli.config_for(app);
    if (cli.check) {
      std::printf("ddswarm-agent: %s: the agent's sections are valid\n", cli.config.c_str());
      return 0;
    }
    return ddswarm::agent::run_agent(cfg, cli.duration_s, argc, argv);
  });
  return ddswarm::end_process(code);
}
