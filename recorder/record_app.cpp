#include "recorder/record_app.hpp"

#include <fmt/format.h>

#include <cstdio>

#include "common/cli_checks.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

namespace ddswarm::gs {

void add_record_command_line(CLI::App& app, RecordCommandLine& cl) {
  app.add_option("-o,--output", cl.opt.path, "output .mcap file");
  app.add_option("--topics", cl.opt.topics, "topics to record (default: all)")->delimiter(',');
  app.add_option("--duration", cl.duration_s,
                 "stop after this many wall seconds (0 = until Ctrl-C)")
      ->check(finite_range(0.0, 1e9));
  app.add_option("--compression", cl.opt.compression, "chunk compression")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}));
  app.add_option("--chunk-kb", cl.chunk_kb,
                 "uncompressed KiB per chunk (a crash loses at most one)")
      ->check(CLI::Range(1, 1 << 20));
  add_dds_options(app, cl.dds);
  cl.info = app.add_subcommand("info", "describe a recording");
  cl.info->add_option("file", cl.info_path, "recording")->required();
  cl.info->add_flag("--messages", cl.list_messages,
                    "also list every message: log time, topic, bytes, payload hash");
}

int run_record(RecordCommandLine& cl) {
  if (*cl.info) {
    std::printf("%s", describe_recording(cl.info_path, cl.list_messages).c_str());
    return 0;
  }
  if (cl.opt.path.empty()) {
    std::fprintf(stderr, "ddswarm-record: error: -o/--output is required\n");
    return 2;
  }
  cl.opt.chunk_bytes = cl.chunk_kb * 1024;
  default_security_role(cl.dds, "recorder");
  install_stop_signals();
  Recorder rec(cl.dds, cl.opt);
  std::fprintf(stderr, "ddswarm-record: recording to %s (Ctrl-C to stop)\n", cl.opt.path.c_str());
  const auto counts = rec.run(cl.duration_s);
  std::fputs(record_summary(counts, cl.opt.path).c_str(), stderr);
  return 0;
}

std::string record_summary(const RecorderCounts& counts, const std::string& path) {
  std::string out;
  std::uint64_t total = 0;
  for (const auto& [topic, n] : counts.messages) {
    const auto missed = counts.missed.count(topic) ? counts.missed.at(topic) : 0;
    const auto note = missed ? fmt::format(" ({} more were sent but never received)", missed) : "";
    if (n || missed) out += fmt::format("  {:<24} {}{}\n", topic, n, note);
    total += n;
  }
  out += fmt::format("ddswarm-record: {} messages, {:.2f} MB written to {} (peak queue {})\n",
                     total, counts.bytes / 1e6, path, counts.max_queue);
  if (counts.rejoins)
    out += fmt::format(
        "ddswarm-record: joined DDS again {} time(s) after a stop longer than the lease; "
        "{} samples received twice were kept once\n",
        counts.rejoins, counts.duplicates);
  return out;
}

void add_replay_command_line(CLI::App& app, ReplayCommandLine& cl) {
  app.add_option("file", cl.path, "recording")->required();
  app.add_option("--rate", cl.rate,
                 "playback speed (2 = twice as fast; above 1 held so that no topic read by "
                 "data-sharing is written over 10,000 times a second: docs/dds.md)")
      ->check(finite_positive());
  app.add_flag("--loop", cl.loop, "start again at the end, until Ctrl-C");
  app.add_option("--topics", cl.topics, "topics to replay (default: all)")->delimiter(',');
  add_dds_options(app, cl.dds);
}

int run_replay(const ReplayCommandLine& cl) {
  install_stop_signals();
  auto n = Replay(cl.dds, cl.path, cl.rate, cl.loop, cl.topics).run();
  std::fprintf(stderr, "ddswarm-replay: %llu messages published\n",
               static_cast<unsigned long long>(n));
  return 0;
}

}  // namespace ddswarm::gs
