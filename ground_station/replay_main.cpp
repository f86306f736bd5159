// ddswarm-replay: republishes a recording with its original timing, so the
// ground station and viewers work on it as on a live run.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "common/cli_checks.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "ground_station/recorder.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-replay", [&]() -> int {
    CLI::App app{"ddswarm-replay: republish an MCAP recording over DDS"};
    std::string path;
    double rate = 1.0;
    bool loop = false;
    std::vector<std::string> topics;
    ddswarm::DdsConfig dds;
    app.add_option("file", path, "recording")->required();
    app.add_option("--rate", rate,
                   "playback speed (2 = twice as fast; above 1 held so that no topic read by "
                   "data-sharing is written over 10,000 times a second: docs/dds.md)")
        ->check(ddswarm::finite_positive());
    app.add_flag("--loop", loop, "start again at the end, until Ctrl-C");
    app.add_option("--topics", topics, "topics to replay (default: all)")->delimiter(',');
    ddswarm::add_dds_options(app, dds);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    ddswarm::install_stop_signals();
    auto n = ddswarm::gs::replay(dds, path, rate, loop, topics);
    std::fprintf(stderr, "ddswarm-replay: %llu messages published\n", static_cast<unsigned long long>(n));
    return 0;
  });
  return ddswarm::end_process(code);
}
