// libFuzzer: the MCAP writer and reader (common/mcap). The first byte picks:
//   even: a round trip. The rest is a script: writer options (compression,
//         chunk size), then messages (channel, time steps, sequence, payload).
//         The file written must read back with every message identical, once,
//         and statistics that match, both from the summary and, with the
//         summary cut off as after a crash, from a scan.
//   odd:  the rest is a file. Reader must read it or refuse it with
//         std::runtime_error; never crash, hang or allocate without bound.
#include <fuzzer/FuzzedDataProvider.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include "common/mcap/mcap_reader.hpp"
#include "common/mcap/mcap_writer.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace ddswarm::mcap;

namespace {

std::string scratch(const char* what) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/ddswarm_fuzz_mcap_" + std::to_string(::getpid()) +
         what;
}

using Key = std::tuple<std::uint64_t, std::uint16_t, std::uint32_t, std::uint64_t,
                       std::vector<std::uint8_t>>;

Key key(const Message& m) {
  return {m.log_time_ns, m.channel_id, m.sequence, m.publish_time_ns, m.data};
}

std::vector<Key> sorted_keys(const std::vector<Message>& ms) {
  std::vector<Key> out;
  for (const auto& m : ms) out.push_back(key(m));
  std::sort(out.begin(), out.end());
  return out;
}

void round_trip(FuzzedDataProvider& fdp) {
  static const std::string path = scratch(".mcap");
  WriterOptions opt;
  const Compression kinds[] = {Compression::none, Compression::zstd, Compression::lz4};
  opt.compression = kinds[fdp.ConsumeIntegralInRange(0, 2)];
  opt.chunk_size_bytes = fdp.ConsumeIntegralInRange<std::uint64_t>(1, 4096);
  opt.fsync_on_close = false;
  std::vector<Message> written;
  {
    Writer w(path, opt);
    const auto schema =
        w.add_schema("ddswarm::msg::DroneState", "omgidl", fdp.ConsumeRandomLengthString(64));
    std::vector<std::uint16_t> channels;
    const int n_channels = fdp.ConsumeIntegralInRange(1, 4);
    for (int i = 0; i < n_channels; ++i)
      channels.push_back(w.add_channel(fdp.ConsumeBool() ? schema : 0,
                                       fdp.ConsumeRandomLengthString(32), "cdr",
                                       {{"k", fdp.ConsumeRandomLengthString(8)}}));
    std::uint64_t t = fdp.ConsumeIntegral<std::uint32_t>();
    const int n = fdp.ConsumeIntegralInRange(0, 200);
    for (int i = 0; i < n && fdp.remaining_bytes() > 0; ++i) {
      Message m;
      m.channel_id = channels[fdp.ConsumeIntegralInRange<std::size_t>(0, channels.size() - 1)];
      // Times may go backwards (a late sample): the reader sorts within a chunk.
      t = fdp.ConsumeBool() ? t + fdp.ConsumeIntegral<std::uint16_t>()
                            : t - std::min<std::uint64_t>(t, fdp.ConsumeIntegral<std::uint8_t>());
      m.log_time_ns = t;
      m.publish_time_ns = fdp.ConsumeIntegral<std::uint64_t>();
      m.sequence = fdp.ConsumeIntegral<std::uint32_t>();
      const std::string payload = fdp.ConsumeRandomLengthString(512);
      m.data.assign(payload.begin(), payload.end());
      w.write(m.channel_id, m.log_time_ns, m.publish_time_ns, m.data.data(), m.data.size(),
              m.sequence);
      written.push_back(m);
    }
    w.close();
  }
  const auto want = sorted_keys(written);
  {
    Reader r(path);
    FUZZ_CHECK(r.how_read().from_summary);
    FUZZ_CHECK(r.statistics().message_count == written.size());
    FUZZ_CHECK(sorted_keys(r.read_messages()) == want);
  }
  // Without its summary and footer (a crash after the last chunk was flushed),
  // a scan must still find every message.
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size < 8 + 20) return;
  std::filesystem::resize_file(path, size - 8,
                               ec);  // drop the trailing magic: the summary is not trusted
  FUZZ_CHECK(!ec);
  Reader scanned(path);
  FUZZ_CHECK(!scanned.how_read().from_summary);
  FUZZ_CHECK(sorted_keys(scanned.read_messages()) == want);
}

void read_any(const std::uint8_t* data, std::size_t size) {
  static const std::string path = scratch("_raw.mcap");
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    Reader r(path);
    (void)r.statistics();
    (void)r.how_read().describe();
    std::size_t n = 0;
    r.for_each_message([&](const MessageView& m) { n += m.data.size() > 0; });
  } catch (const std::runtime_error&) {
    // refused with a message: fine
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if (size > 256 * 1024) return -1;
  if (data[0] % 2 == 0) {
    FuzzedDataProvider fdp(data + 1, size - 1);
    round_trip(fdp);
  } else {
    read_any(data + 1, size - 1);
  }
  return 0;
}
