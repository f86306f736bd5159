// ddswarm-launch: starts the server and one agent process per drone (and
// optionally ground-station commands), prefixes their logs, supervises them
// (launcher/launch.hpp).
#include <CLI/CLI.hpp>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "launcher/launch.hpp"

int main(int argc, char** argv) {
  using namespace ddswarm;
  const int code = run_main("ddswarm-launch", [&]() -> int {
    CLI::App app{"ddswarm-launch: start the server and one agent process per drone"};
    gs::LaunchCommandLine cl;
    gs::add_launch_command_line(app, cl);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    // Before the scenario's copy is written: SIGINT or SIGTERM while it is
    // checked end the launch through its normal end, which removes the copy.
    install_stop_signals();
    gs::LaunchApp launch(app, std::move(cl));
    return launch.run();
  });
  return end_process(code);
}
