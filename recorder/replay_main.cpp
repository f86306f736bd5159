// ddswarm-replay: republishes a recording with its original timing, so the
// ground station and viewers work on it as on a live run (recorder/record_app.hpp).
#include <CLI/CLI.hpp>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "recorder/record_app.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-replay", [&]() -> int {
    CLI::App app{"ddswarm-replay: republish an MCAP recording over DDS"};
    ddswarm::gs::ReplayCommandLine cl;
    ddswarm::gs::add_replay_command_line(app, cl);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    return ddswarm::gs::run_replay(cl);
  });
  return ddswarm::end_process(code);
}
