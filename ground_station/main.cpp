// ddswarm-gs: the ground station. Without a subcommand it opens the
// interactive console (thesis Fig. 9); subcommands script the same actions
// (ground_station/subcommands.hpp).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "ground_station/subcommands.hpp"

int main(int argc, char** argv) {
  using namespace ddswarm;
  const int rc = run_main("ddswarm-gs", [&]() -> int {
    CLI::App app{"ddswarm-gs: the ground station (console, scripted commands, experiments)"};
    gs::GsCommandLine cl;
    gs::add_gs_command_line(app, cl);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    return gs::run_gs(app, cl);
  });
  // Ctrl-C or SIGTERM cut a subcommand short: say so (the menu and trace end
  // normally on it and keep their 0).
  if (stop_requested() && rc != 0 && rc != 2) {
    std::fprintf(stderr, "ddswarm-gs: interrupted\n");
    return end_process(130);
  }
  return end_process(rc);
}
