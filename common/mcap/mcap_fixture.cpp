// Writes a known MCAP file for tests/mcap_reader_test.sh, and prints, one
// "topic=count" line each, how many messages of each topic a reader must find.
//
// Content: 3000 ticks of 1 ms; /ddswarm/drone_state every tick (200 B),
// /ddswarm/command every 3rd (64 B), /ddswarm/clock every 6th (16 B); payloads
// from a fixed seed. With --crash-after-chunks N the process dies (_Exit,
// no close) once N chunks are complete and more messages sit in the open
// chunk: the printed counts are those of the complete chunks.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>

#include "common/mcap/mcap_writer.hpp"

namespace mcap = ddswarm::mcap;

int main(int argc, char** argv) {
  CLI::App app{"Write a known MCAP file for reader tests"};
  std::string out, compression = "zstd";
  unsigned crash_after_chunks = 0;
  app.add_option("output", out, "MCAP file to write")->required();
  app.add_option("--compression", compression, "zstd, lz4 or none")
      ->check(CLI::IsMember({"zstd", "lz4", "none"}));
  app.add_option("--crash-after-chunks", crash_after_chunks,
                 "die without closing once this many chunks are complete (0: close normally)");
  CLI11_PARSE(app, argc, argv);

  try {
    mcap::WriterOptions opt;
    opt.compression = compression == "zstd"  ? mcap::Compression::zstd
                      : compression == "lz4" ? mcap::Compression::lz4
                                             : mcap::Compression::none;
    opt.compression_level = compression == "lz4" ? 0 : 1;
    opt.chunk_size_bytes = 64 * 1024;
    mcap::Writer w(out, opt);

    struct Topic {
      const char* topic;
      const char* type;
      unsigned every;
      std::size_t size;
      std::uint16_t id = 0;
      std::uint64_t count = 0, durable = 0;
    };
    Topic topics[] = {{"/ddswarm/drone_state", "ddswarm::idl::DroneState", 1, 200},
                      {"/ddswarm/command", "ddswarm::idl::Command", 3, 64},
                      {"/ddswarm/clock", "ddswarm::idl::Clock", 6, 16}};
    for (auto& t : topics) {
      const std::string idl = std::string("module ddswarm { module idl { struct ") +
                              (std::strrchr(t.type, ':') + 1) + " { octet payload[" +
                              std::to_string(t.size) + "]; }; }; };\n";
      const auto schema = w.add_schema(t.type, "omgidl", idl);
      t.id = w.add_channel(schema, t.topic, "cdr", {{"qos", "reliable"}});
    }

    std::mt19937 rng(42);
    std::vector<std::uint8_t> payload;
    auto print_counts = [&](bool durable) {
      for (const auto& t : topics)
        std::cout << t.topic << '=' << (durable ? t.durable : t.count) << '\n';
      std::cout.flush();
    };
    std::uint64_t chunks_seen = 0;
    for (unsigned tick = 0; tick < 3000; ++tick) {
      const std::uint64_t t_ns = 1'000'000'000ull + tick * 1'000'000ull;
      for (auto& t : topics) {
        if (tick % t.every) continue;
        payload.resize(t.size);
        for (auto& b : payload) b = std::uint8_t(rng());
        w.write(t.id, t_ns, t_ns - 250'000, payload.data(), payload.size());
        ++t.count;
        if (w.chunks_written() == chunks_seen) continue;
        // This write closed a chunk, which holds every message written so far.
        chunks_seen = w.chunks_written();
        for (auto& d : topics) d.durable = d.count;
        if (chunks_seen != crash_after_chunks) continue;
        payload.assign(topics[0].size, 0xAB);
        for (unsigned extra = 1; extra <= 20; ++extra)  // lost with the open chunk
          w.write(topics[0].id, t_ns + extra, t_ns + extra, payload.data(), payload.size());
        print_counts(true);
        std::_Exit(0);
      }
    }
    w.close();
    print_counts(false);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "mcap_fixture: " << e.what() << '\n';
    return 1;
  }
}
