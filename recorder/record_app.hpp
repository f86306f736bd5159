#pragma once
// ddswarm-record and ddswarm-replay's command lines and what they run, so
// that their mains (record_main.cpp, replay_main.cpp) only parse, build and run.
#include <CLI/CLI.hpp>
#include <cstddef>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "recorder/recorder.hpp"

namespace ddswarm::gs {

/// Everything ddswarm-record's command line sets, with the defaults --help shows.
struct RecordCommandLine {
  RecorderOptions opt;
  double duration_s = 0;
  std::size_t chunk_kb = 1024;
  DdsConfig dds;
  CLI::App* info = nullptr;  ///< `info FILE`
  std::string info_path;
  bool list_messages = false;
};

/// Adds ddswarm-record's options and its `info` subcommand to app, bound to cl.
void add_record_command_line(CLI::App& app, RecordCommandLine& cl);

/// `ddswarm-record info` or a recording until Ctrl-C or --duration; returns
/// the exit code (2: no output file named).
int run_record(RecordCommandLine& cl);

/// What ddswarm-record says on stderr when it has finished: a line per topic
/// it recorded or missed samples of, then the totals.
std::string record_summary(const RecorderCounts& counts, const std::string& path);

/// Everything ddswarm-replay's command line sets, with the defaults --help shows.
struct ReplayCommandLine {
  std::string path;
  double rate = 1.0;
  bool loop = false;
  std::vector<std::string> topics;
  DdsConfig dds;
};

/// Adds ddswarm-replay's arguments and options to app, bound to cl.
void add_replay_command_line(CLI::App& app, ReplayCommandLine& cl);

/// Replays the recording; returns the exit code.
int run_replay(const ReplayCommandLine& cl);

}  // namespace ddswarm::gs
