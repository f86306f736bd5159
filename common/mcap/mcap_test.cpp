#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include "common/config_error.hpp"
#include "common/mcap/mcap_reader.hpp"
#include "common/mcap/mcap_writer.hpp"

using namespace ddswarm::mcap;
namespace fs = std::filesystem;

namespace {

struct Written {
  std::uint16_t channel_id;
  std::uint32_t sequence;
  std::uint64_t log_ns, publish_ns;
  std::vector<std::uint8_t> data;
};

class McapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised names hold a '/'
    dir_ = fs::temp_directory_path() / ("mcap_test_" + std::to_string(::getpid()) + "_" + name);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  // Three channels on two schemas; `n` messages of 0..1500 bytes at 1 ms steps,
  // channel i+1 getting every message with index % 3 == i, payloads seeded.
  std::vector<Written> write_file(const std::string& path, WriterOptions opt, int n,
                                  int flush_every = 0) {
    Writer w(path, opt);
    const auto state = w.add_schema("ddswarm::idl::DroneState", "omgidl",
                                    "module ddswarm { struct DroneState { long id; }; };");
    const auto cmd = w.add_schema("ddswarm::idl::Command", "omgidl",
                                  "module ddswarm { struct Command { long id; }; };");
    std::uint16_t ch[3] = {w.add_channel(state, "/swarm/state", "cdr", {{"qos", "best_effort"}}),
                           w.add_channel(cmd, "/swarm/command", "cdr", {{"qos", "reliable"}}),
                           w.add_channel(state, "/swarm/state_ground", "cdr")};
    std::mt19937 rng(7);
    std::vector<Written> out;
    std::uint32_t seq[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      Written m;
      m.channel_id = ch[i % 3];
      m.sequence = seq[i % 3]++;
      m.log_ns = 1'000'000'000ull + std::uint64_t(i) * 1'000'000ull;
      m.publish_ns = m.log_ns - 17;
      m.data.resize(i % 97 == 0 ? 0 : rng() % 1500);
      // Compressible but not trivial: a slowly varying pattern plus noise.
      for (std::size_t k = 0; k < m.data.size(); ++k)
        m.data[k] = std::uint8_t((k / 8 + i) ^ (rng() % 4));
      w.write(m.channel_id, m.log_ns, m.publish_ns, m.data.data(), m.data.size());
      out.push_back(std::move(m));
      if (flush_every && (i + 1) % flush_every == 0) w.flush_chunk();
    }
    EXPECT_EQ(w.messages_written(), std::uint64_t(n));
    w.close();
    EXPECT_EQ(w.bytes_written(), fs::file_size(path));
    return out;
  }

  static void expect_messages(const Reader& r, const std::vector<Written>& want, std::size_t n) {
    const auto got = r.read_messages();
    ASSERT_EQ(got.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      SCOPED_TRACE("message " + std::to_string(i));
      EXPECT_EQ(got[i].channel_id, want[i].channel_id);
      EXPECT_EQ(got[i].sequence, want[i].sequence);
      EXPECT_EQ(got[i].log_time_ns, want[i].log_ns);
      EXPECT_EQ(got[i].publish_time_ns, want[i].publish_ns);
      ASSERT_EQ(got[i].data, want[i].data);
    }
  }

  std::string copy_prefix(const std::string& from, std::uint64_t n, const std::string& name) {
    std::ifstream in(from, std::ios::binary);
    std::vector<char> bytes(n);
    in.read(bytes.data(), std::streamsize(n));
    const auto to = file(name);
    std::ofstream(to, std::ios::binary).write(bytes.data(), std::streamsize(n));
    return to;
  }

  static void flip_byte(const std::string& path, std::uint64_t at) {
    std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
    f.seekg(std::streamoff(at));
    char c = 0;
    f.get(c);
    f.seekp(std::streamoff(at));
    f.put(char(c ^ 0x5A));
  }

  static std::string error_of(const std::function<void()>& fn) {
    try {
      fn();
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

class McapRoundTrip : public McapTest, public ::testing::WithParamInterface<Compression> {};

TEST_P(McapRoundTrip, EveryMessageSchemaChannelAndStatisticComesBack) {
  WriterOptions opt;
  opt.compression = GetParam();
  opt.compression_level = GetParam() == Compression::lz4 ? 0 : 1;
  opt.chunk_size_bytes = 64 * 1024;
  const auto path = file("round_trip.mcap");
  const auto want = write_file(path, opt, 6000);

  Reader r(path);
  EXPECT_EQ(r.how_read().describe(), "summary");
  EXPECT_EQ(r.header_library(), "ddswarm");
  ASSERT_EQ(r.schemas().size(), 2u);
  EXPECT_EQ(r.schemas().at(1).name, "ddswarm::idl::DroneState");
  EXPECT_EQ(r.schemas().at(1).encoding, "omgidl");
  EXPECT_EQ(r.schemas().at(2).data, "module ddswarm { struct Command { long id; }; };");
  ASSERT_EQ(r.channels().size(), 3u);
  EXPECT_EQ(r.channel(1)->topic, "/swarm/state");
  EXPECT_EQ(r.channel(2)->schema_id, 2);
  EXPECT_EQ(r.channel(2)->message_encoding, "cdr");
  EXPECT_EQ(r.channel(2)->metadata.at("qos"), "reliable");
  EXPECT_TRUE(r.channel(3)->metadata.empty());
  EXPECT_EQ(r.channel(4), nullptr);

  const auto& st = r.statistics();
  EXPECT_EQ(st.message_count, 6000u);
  EXPECT_EQ(st.schema_count, 2);
  EXPECT_EQ(st.channel_count, 3u);
  EXPECT_EQ(st.channel_message_counts,
            (std::map<std::uint16_t, std::uint64_t>{{1, 2000}, {2, 2000}, {3, 2000}}));
  EXPECT_EQ(st.message_start_time_ns, 1'000'000'000u);
  EXPECT_EQ(st.message_end_time_ns, 1'000'000'000ull + 5999ull * 1'000'000ull);
  EXPECT_GT(st.chunk_count, 40u);  // ~4.5 MB of payload in 64 KiB chunks
  EXPECT_EQ(r.chunks().size(), st.chunk_count);
  for (const auto& c : r.chunks()) EXPECT_EQ(c.compression, compression_name(GetParam()));
  if (GetParam() != Compression::none) {
    EXPECT_LT(r.chunks()[0].compressed_size, r.chunks()[0].uncompressed_size);
  }
  expect_messages(r, want, want.size());
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapRoundTrip,
                         ::testing::Values(Compression::zstd, Compression::lz4, Compression::none),
                         [](const auto& info) {
                           return std::string(info.param == Compression::none
                                                  ? "none"
                                                  : compression_name(info.param));
                         });

TEST_F(McapTest, ScanWithoutSummaryComputesTheSameStatistics) {
  const auto path = file("stats.mcap");
  const auto want = write_file(path, {}, 3000, 500);
  Reader indexed(path);
  // Break the summary CRC (its last byte sits just before the trailing magic).
  flip_byte(path, fs::file_size(path) - 9);
  Reader scanned(path);
  EXPECT_FALSE(scanned.how_read().from_summary);
  EXPECT_FALSE(scanned.how_read().truncated);
  EXPECT_EQ(scanned.how_read().describe().rfind("scanned, complete (summary CRC mismatch", 0), 0u)
      << scanned.how_read().describe();
  const auto& a = indexed.statistics();
  const auto& b = scanned.statistics();
  EXPECT_EQ(b.message_count, a.message_count);
  EXPECT_EQ(b.schema_count, a.schema_count);
  EXPECT_EQ(b.channel_count, a.channel_count);
  EXPECT_EQ(b.chunk_count, a.chunk_count);
  EXPECT_EQ(b.chunk_count, 6u);
  EXPECT_EQ(b.message_start_time_ns, a.message_start_time_ns);
  EXPECT_EQ(b.message_end_time_ns, a.message_end_time_ns);
  EXPECT_EQ(b.channel_message_counts, a.channel_message_counts);
  expect_messages(scanned, want, want.size());
}

TEST_F(McapTest, TruncatedFileReadsEveryMessageOfItsCompleteChunks) {
  const auto path = file("full.mcap");
  const auto want = write_file(path, {}, 5000, 1000);  // 5 chunks of 1000 messages
  const auto chunks = Reader(path).chunks();
  ASSERT_EQ(chunks.size(), 5u);
  struct Cut {
    const char* what;
    std::uint64_t at;
  };
  const Cut cuts[] = {
      {"after chunk 2 and its message indexes", chunks[2].offset},
      {"after chunk 2, before its message indexes", chunks[1].offset + chunks[1].length},
      {"in the middle of chunk 3", chunks[2].offset + chunks[2].length / 2},
      {"in chunk 3's record header", chunks[2].offset + 5},
  };
  for (const auto& cut : cuts) {
    SCOPED_TRACE(cut.what);
    Reader r(copy_prefix(path, cut.at, "cut.mcap"));
    const auto& how = r.how_read();
    EXPECT_FALSE(how.from_summary);
    EXPECT_TRUE(how.truncated);
    const std::uint64_t valid =
        cut.at <= chunks[2].offset ? cut.at : chunks[2].offset;  // last complete record's end
    EXPECT_EQ(how.valid_bytes, valid);
    EXPECT_EQ(
        how.describe().rfind("scanned, truncated after " + std::to_string(valid) + " bytes", 0), 0u)
        << how.describe();
    EXPECT_EQ(r.statistics().message_count, 2000u);
    EXPECT_EQ(r.statistics().chunk_count, 2u);
    EXPECT_EQ(r.channels().size(), 3u);
    expect_messages(r, want, 2000);
  }
}

TEST_F(McapTest, KilledWriterLeavesEveryCompletedChunkReadable) {
  const auto path = file("killed.mcap");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {  // the "recorder": 2 complete chunks, then dies with 500 in the open one
    WriterOptions opt;
    opt.chunk_size_bytes = 1u << 30;
    Writer w(path, opt);
    const auto ch = w.add_channel(w.add_schema("S", "omgidl", "struct S {};"), "/t", "cdr");
    for (std::uint32_t i = 0; i < 2500; ++i) {
      w.write(ch, i, i, reinterpret_cast<const std::uint8_t*>(&i), sizeof i);
      if (i % 1000 == 999) w.flush_chunk();
    }
    std::_Exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  Reader r(path);
  EXPECT_TRUE(r.how_read().truncated);
  EXPECT_EQ(r.channels().at(1).topic, "/t");
  const auto got = r.read_messages();
  ASSERT_EQ(got.size(), 2000u);
  for (std::uint32_t i = 0; i < 2000; ++i) {
    std::uint32_t v = 0;
    std::memcpy(&v, got[i].data.data(), sizeof v);
    ASSERT_EQ(v, i);
  }
}

TEST_F(McapTest, UnwritablePathThrowsNamingPathAndReason) {
  const auto bad = file("no/such/dir/x.mcap");
  const auto msg = error_of([&] { Writer w(bad); });
  EXPECT_NE(msg.find(bad), std::string::npos) << msg;
  EXPECT_NE(msg.find("No such file or directory"), std::string::npos) << msg;
  const auto dir_msg = error_of([&] { Writer w(dir_.string()); });
  EXPECT_NE(dir_msg.find("Is a directory"), std::string::npos) << dir_msg;
}

TEST_F(McapTest, FullDiskIsDetected) {
  const auto msg = error_of([] {
    Writer w("/dev/full");
    const std::uint8_t b[4] = {1, 2, 3, 4};
    w.write(w.add_channel(0, "/t", "cdr"), 1, 1, b, sizeof b);
    w.close();
  });
  EXPECT_NE(msg.find("/dev/full"), std::string::npos) << msg;
  EXPECT_NE(msg.find("No space left on device"), std::string::npos) << msg;
}

TEST_F(McapTest, WriteFailureMidRecordingIsReportedAndCloseFailsToo) {
  // A file size limit makes writes fail part-way, as a filling disk would.
  const auto path = file("limited.mcap");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::signal(SIGXFSZ, SIG_IGN);
    rlimit lim{200 * 1024, 200 * 1024};
    ::setrlimit(RLIMIT_FSIZE, &lim);
    WriterOptions opt;
    opt.compression = Compression::none;
    opt.chunk_size_bytes = 32 * 1024;
    Writer w(path, opt);
    const auto ch = w.add_channel(0, "/t", "cdr");
    std::vector<std::uint8_t> b(1000, 7);
    std::string first;
    try {
      for (int i = 0; i < 1000; ++i) w.write(ch, i, i, b.data(), b.size());
    } catch (const std::runtime_error& e) {
      first = e.what();
    }
    if (first.empty()) std::_Exit(10);
    if (first.find(path) == std::string::npos || first.find("File too large") == std::string::npos)
      std::_Exit(11);
    // The writer stays failed: no further write, and close() reports it again, once.
    try {
      w.write(ch, 0, 0, b.data(), b.size());
      std::_Exit(12);
    } catch (const std::runtime_error&) {
    }
    try {
      w.close();
      std::_Exit(13);
    } catch (const std::runtime_error&) {
    }
    w.close();
    std::_Exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "10: no error; 11: error without path or reason; 12: write "
                                       "after failure; 13: close succeeded";
  // What reached the disk is still a readable prefix.
  Reader r(path);
  EXPECT_TRUE(r.how_read().truncated);
  EXPECT_GT(r.read_messages().size(), 100u);
}

TEST_F(McapTest, CorruptChunkIsDetectedAndNamesItsOffset) {
  WriterOptions opt;
  opt.compression = Compression::none;  // so the flipped byte reaches the CRC check
  const auto path = file("crc.mcap");
  write_file(path, opt, 3000, 1000);
  const auto chunk = Reader(path).chunks().at(1);
  flip_byte(path, chunk.offset + chunk.length - 100);

  Reader r(path);  // the summary is intact
  const auto msg = error_of([&] { r.read_messages(); });
  EXPECT_NE(msg.find("chunk at offset " + std::to_string(chunk.offset)), std::string::npos) << msg;
  EXPECT_NE(msg.find("CRC mismatch"), std::string::npos) << msg;

  // Without the footer the scan meets the same chunk while opening.
  const auto cut = copy_prefix(path, fs::file_size(path) - 1, "crc_cut.mcap");
  const auto scan_msg = error_of([&] { Reader s(cut); });
  EXPECT_NE(scan_msg.find("chunk at offset " + std::to_string(chunk.offset)), std::string::npos)
      << scan_msg;
}

TEST_F(McapTest, CorruptCompressedChunkIsDetected) {
  for (auto c : {Compression::zstd, Compression::lz4}) {
    WriterOptions opt;
    opt.compression = c;
    opt.compression_level = c == Compression::lz4 ? 0 : 1;
    const auto path = file("z.mcap");
    write_file(path, opt, 2000, 1000);
    const auto chunk = Reader(path).chunks().at(0);
    flip_byte(path, chunk.offset + chunk.length / 2);
    const auto msg = error_of([&] { Reader(path).read_messages(); });
    EXPECT_NE(msg.find("chunk at offset " + std::to_string(chunk.offset)), std::string::npos)
        << compression_name(c) << ": " << msg;
  }
}

TEST_F(McapTest, MessagesOfAChunkComeBackInLogTimeOrder) {
  const auto path = file("order.mcap");
  {
    Writer w(path);
    const auto ch = w.add_channel(0, "/t", "cdr");
    for (std::uint64_t t : {50, 30, 40, 30, 10}) w.write(ch, t, t, nullptr, 0);
  }
  Reader r(path);
  std::vector<std::uint64_t> times;
  std::vector<std::uint32_t> seqs;
  r.for_each_message([&](const MessageView& m) {
    times.push_back(m.log_time_ns);
    seqs.push_back(m.sequence);
  });
  EXPECT_EQ(times, (std::vector<std::uint64_t>{10, 30, 30, 40, 50}));
  EXPECT_EQ(seqs, (std::vector<std::uint32_t>{4, 1, 3, 2, 0}));
  EXPECT_EQ(r.statistics().message_start_time_ns, 10u);
  EXPECT_EQ(r.statistics().message_end_time_ns, 50u);
}

TEST_F(McapTest, EmptyFileIsValid) {
  const auto path = file("empty.mcap");
  Writer(path).close();
  Reader r(path);
  EXPECT_EQ(r.how_read().describe(), "summary");
  EXPECT_EQ(r.statistics().message_count, 0u);
  EXPECT_TRUE(r.read_messages().empty());
}

TEST_F(McapTest, MisuseIsRejected) {
  WriterOptions bad;
  bad.chunk_size_bytes = 0;
  EXPECT_EQ(error_of([&] { bad.validate(); }), "mcap.chunk_size_bytes = 0: must be > 0");
  bad = {};
  bad.compression_level = 40;
  EXPECT_THROW(bad.validate(), ddswarm::FieldError);

  const auto path = file("misuse.mcap");
  Writer w(path);
  EXPECT_THROW(w.add_channel(3, "/t", "cdr"), std::invalid_argument);
  EXPECT_THROW(w.write(1, 0, 0, nullptr, 0), std::invalid_argument);
  w.close();
  w.close();  // idempotent
  EXPECT_THROW(w.write(1, 0, 0, nullptr, 0), std::logic_error);

  std::ofstream(file("text.mcap")) << "hello, not an mcap file";
  EXPECT_NE(error_of([&] { Reader r(file("text.mcap")); }).find("not an MCAP file"),
            std::string::npos);
  EXPECT_NE(error_of([&] { Reader r(file("missing.mcap")); }).find("missing.mcap: cannot open"),
            std::string::npos);
}

}  // namespace
