// ddswarm-record: records the swarm's DDS traffic to an MCAP file;
// `ddswarm-record info FILE` describes a recording.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdio>

#include "common/cli_checks.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "ground_station/recorder.hpp"

int main(int argc, char** argv) {
  const int code = ddswarm::run_main("ddswarm-record", [&]() -> int {
    CLI::App app{"ddswarm-record: record every ddswarm topic (or some) to MCAP"};
    ddswarm::gs::RecorderOptions opt;
    double duration_s = 0;
    std::size_t chunk_kb = 1024;
    ddswarm::DdsConfig dds;
    app.add_option("-o,--output", opt.path, "output .mcap file");
    app.add_option("--topics", opt.topics, "topics to record (default: all)")->delimiter(',');
    app.add_option("--duration", duration_s, "stop after this many wall seconds (0 = until Ctrl-C)")
        ->check(ddswarm::finite_range(0.0, 1e9));
    app.add_option("--compression", opt.compression, "chunk compression")
        ->check(CLI::IsMember({"zstd", "lz4", "none"}));
    app.add_option("--chunk-kb", chunk_kb, "uncompressed KiB per chunk (a crash loses at most one)")
        ->check(CLI::Range(1, 1 << 20));
    ddswarm::add_dds_options(app, dds);
    auto* info = app.add_subcommand("info", "describe a recording");
    std::string info_path;
    info->add_option("file", info_path, "recording")->required();
    bool list_messages = false;
    info->add_flag("--messages", list_messages, "also list every message: log time, topic, bytes, payload hash");
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    if (*info) {
      std::printf("%s", ddswarm::gs::describe_recording(info_path, list_messages).c_str());
      return 0;
    }
    if (opt.path.empty()) {
      std::fprintf(stderr, "ddswarm-record: error: -o/--output is required\n");
      return 2;
    }
    opt.chunk_bytes = chunk_kb * 1024;
    ddswarm::default_security_role(dds, "recorder");
    ddswarm::install_stop_signals();
    ddswarm::gs::Recorder rec(dds, opt);
    std::fprintf(stderr, "ddswarm-record: recording to %s (Ctrl-C to stop)\n", opt.path.c_str());
    auto counts = rec.run(duration_s);
    std::uint64_t total = 0;
    for (const auto& [topic, n] : counts.messages) {
      const auto missed = counts.missed.count(topic) ? counts.missed.at(topic) : 0;
      const auto note = missed ? fmt::format(" ({} more were sent but never received)", missed) : "";
      if (n || missed)
        std::fprintf(stderr, "  %-24s %llu%s\n", topic.c_str(), static_cast<unsigned long long>(n),
                     note.c_str());
      total += n;
    }
    std::fprintf(stderr, "ddswarm-record: %llu messages, %.2f MB written to %s (peak queue %zu)\n",
                 static_cast<unsigned long long>(total), counts.bytes / 1e6, opt.path.c_str(),
                 counts.max_queue);
    if (counts.rejoins)
      std::fprintf(
          stderr,
          "ddswarm-record: joined DDS again %d time(s) after a stop longer than the lease; "
          "%llu samples received twice were kept once\n",
          counts.rejoins, static_cast<unsigned long long>(counts.duplicates));
    return 0;
  });
  return ddswarm::end_process(code);
}
