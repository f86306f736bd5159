// ddswarm-record: records the swarm's DDS traffic to an MCAP file;
// `ddswarm-record info FILE` describes a recording (recorder/record_app.hpp).
#include <CLI/CLI.hpp>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "recorder/record_app.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-record", [&]() -> int {
    CLI::App app{"ddswarm-record: record every ddswarm topic (or some) to MCAP"};
    ddswarm::gs::RecordCommandLine cl;
    ddswarm::gs::add_record_command_line(app, cl);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    return ddswarm::gs::run_record(cl);
  });
  return ddswarm::end_process(code);
}
