// Reads a recording and reports what a recorder must guarantee: per topic,
// messages, rate and throughput, and gaps in the tick sequences (per drone
// for keyed topics). Exit 1 when a stream has a gap (a dropped sample).
#include <cstdio>
#include <map>
#include <numeric>
#include <set>

#include "common/mcap/mcap_reader.hpp"
#include "common/topics.hpp"

using namespace ddswarm;

template <class T>
bool decode(std::span<const std::uint8_t> bytes, T& out) {
  typename Topic<T>::PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t p(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), p.data);
  p.length = static_cast<std::uint32_t>(bytes.size());
  return type.deserialize(&p, &out);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: record_check FILE.mcap\n");
    return 2;
  }
  mcap::Reader r(argv[1]);
  // step: the gcd of every tick's distance from the first, so a stream sent
  // every k-th tick (scans at a sensor rate below the control rate) counts
  // only the ticks it would have sent as gaps.
  struct Stream {
    std::uint64_t first = 0, last = 0, n = 0, step = 0;
  };
  std::map<std::string, std::map<int, Stream>> ticks;  // topic -> drone (-1: whole swarm) -> ticks
  std::map<std::string, std::uint64_t> count, bytes;
  std::uint64_t t0 = ~0ULL, t1 = 0;
  r.for_each_message([&](const mcap::MessageView& m) {
    const std::string topic = r.channel(m.channel_id)->topic;
    ++count[topic];
    bytes[topic] += m.data.size();
    t0 = std::min(t0, m.log_time_ns);
    t1 = std::max(t1, m.log_time_ns);
    auto note = [&](int key, std::uint64_t tick) {
      auto& s = ticks[topic][key];
      if (s.n == 0) s.first = tick;
      s.step = std::gcd(s.step, tick > s.first ? tick - s.first : s.first - tick);
      s.last = std::max(s.last, tick);
      ++s.n;
    };
    if (topic == Topic<msg::SwarmState>::name) {
      msg::SwarmState s;
      if (decode(m.data, s)) note(-1, s.tick());
    } else if (topic == Topic<msg::DroneState>::name) {
      msg::DroneState d;
      if (decode(m.data, d)) note(d.drone_id(), d.tick());
    } else if (topic == Topic<msg::DistanceScan>::name) {
      msg::DistanceScan d;
      if (decode(m.data, d)) note(d.drone_id(), d.tick());
    }
  });
  const double dur = (t1 - t0) * 1e-9;
  std::uint64_t total = 0, total_bytes = 0;
  std::printf("%-24s %10s %12s %10s %10s\n", "topic", "messages", "msgs/s", "MB/s", "gaps");
  bool gap = false;
  for (const auto& [topic, n] : count) {
    std::uint64_t missing = 0;
    for (const auto& [key, s] : ticks[topic]) {
      // Republished ticks (lockstep waits) can repeat; a gap is a tick never seen.
      const std::uint64_t span = s.step == 0 ? 1 : (s.last - s.first) / s.step + 1;
      if (s.n < span) missing += span - s.n;
    }
    gap |= missing > 0;
    total += n;
    total_bytes += bytes[topic];
    std::printf("%-24s %10llu %12.0f %10.2f %10llu\n", topic.c_str(),
                static_cast<unsigned long long>(n), n / dur, bytes[topic] / dur / 1e6,
                static_cast<unsigned long long>(missing));
  }
  std::printf("%-24s %10llu %12.0f %10.2f   over %.1f s (%s)\n", "total",
              static_cast<unsigned long long>(total), total / dur, total_bytes / dur / 1e6, dur,
              r.how_read().describe().c_str());
  if (total == 0) {
    std::fprintf(stderr, "record_check: %s holds no message\n", argv[1]);
    return 1;
  }
  return gap ? 1 : 0;
}
