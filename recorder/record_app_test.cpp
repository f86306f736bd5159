// ddswarm-record's closing summary, and the recorder and the replay stopped
// from another thread, as a test hosting them in one process stops them.
#include "recorder/record_app.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <thread>

#include "common/process.hpp"

namespace ddswarm::gs {
namespace {

/// The summary as ddswarm-record printed it with printf before it was a function.
std::string printf_summary(const RecorderCounts& counts, const std::string& path) {
  std::string out;
  char line[512];
  std::uint64_t total = 0;
  for (const auto& [topic, n] : counts.messages) {
    const auto missed = counts.missed.count(topic) ? counts.missed.at(topic) : 0;
    const std::string note =
        missed ? " (" + std::to_string(missed) + " more were sent but never received)" : "";
    if (n || missed) {
      std::snprintf(line, sizeof line, "  %-24s %llu%s\n", topic.c_str(),
                    static_cast<unsigned long long>(n), note.c_str());
      out += line;
    }
    total += n;
  }
  std::snprintf(
      line, sizeof line, "ddswarm-record: %llu messages, %.2f MB written to %s (peak queue %zu)\n",
      static_cast<unsigned long long>(total), counts.bytes / 1e6, path.c_str(), counts.max_queue);
  out += line;
  if (counts.rejoins) {
    std::snprintf(line, sizeof line,
                  "ddswarm-record: joined DDS again %d time(s) after a stop longer than the lease; "
                  "%llu samples received twice were kept once\n",
                  counts.rejoins, static_cast<unsigned long long>(counts.duplicates));
    out += line;
  }
  return out;
}

TEST(RecordSummary, SaysWhatEachTopicGotAndMissedAsItAlwaysHas) {
  RecorderCounts c;
  c.messages = {{"ddswarm/swarm_state", 2783}, {"ddswarm/scene", 0}, {"ddswarm/mission_ack", 0}};
  c.missed = {{"ddswarm/mission_ack", 2}};
  c.bytes = 1234567;
  c.max_queue = 5;
  const std::string s = record_summary(c, "run.mcap");
  EXPECT_EQ(s, printf_summary(c, "run.mcap"));
  EXPECT_EQ(s,
            "  ddswarm/mission_ack      0 (2 more were sent but never received)\n"
            "  ddswarm/swarm_state      2783\n"
            "ddswarm-record: 2783 messages, 1.23 MB written to run.mcap (peak queue 5)\n");
  c.rejoins = 1;
  c.duplicates = 4;
  EXPECT_EQ(record_summary(c, "run.mcap"), printf_summary(c, "run.mcap"));
  c.messages["a_topic_name_longer_than_24_chars"] = 1;
  EXPECT_EQ(record_summary(c, "run.mcap"), printf_summary(c, "run.mcap"));
}

/// A DDS domain of this test's own (140-159: apart from the other unit tests').
int random_test_domain() { return 140 + static_cast<int>(random_instance() % 20); }

TEST(Recorder, StopEndsTheRecordingAndTheFileIsComplete) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("gs_record_app_test_" + std::to_string(getpid()) + ".mcap");
  DdsConfig dds;
  dds.domain_id = random_test_domain();
  RecorderOptions opt;
  opt.path = path.string();
  {
    Recorder rec(dds, opt);
    std::thread stopper([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      rec.stop();
    });
    const double t0 = wall_seconds();
    const auto counts = rec.run(0);  // 0: until stopped
    stopper.join();
    EXPECT_LT(wall_seconds() - t0, 5.0);
    EXPECT_GT(counts.bytes, 0u);
  }
  EXPECT_NE(describe_recording(path.string()).find("duration"), std::string::npos);

  // The replay of it, looping, ends on stop() too.
  Replay replay(dds, path.string(), 1.0, /*loop=*/true, {});
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(2000));
    replay.stop();
  });
  const double t0 = wall_seconds();
  EXPECT_EQ(replay.run(), 0u);  // nothing was recorded
  stopper.join();
  EXPECT_LT(wall_seconds() - t0, 8.0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace ddswarm::gs
