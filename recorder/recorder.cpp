#include "recorder/recorder.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "common/mcap/mcap_reader.hpp"
#include "common/mcap/mcap_writer.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/recorded_sample.hpp"
#include "ddswarm_idl_text.hpp"
#include "recorder/sequence_gaps.hpp"

namespace ddswarm::gs {

namespace {

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

/// The CDR bytes of a sample, encapsulation header included (as on the wire).
template <class T>
std::vector<std::uint8_t> to_cdr(const T& sample) {
  typename Topic<T>::PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(
      type.getSerializedSizeProvider(const_cast<T*>(&sample))());
  if (!type.serialize(const_cast<T*>(&sample), &payload))
    throw std::runtime_error(std::string("cannot serialize a sample of ") + Topic<T>::name);
  return std::vector<std::uint8_t>(payload.data, payload.data + payload.length);
}

/// net.core.rmem_max, the most a UDP socket's receive buffer may hold; 0
/// when it cannot be read.
long udp_receive_buffer_cap() {
  long bytes = 0;
  if (std::FILE* f = std::fopen("/proc/sys/net/core/rmem_max", "r")) {
    if (std::fscanf(f, "%ld", &bytes) != 1) bytes = 0;
    std::fclose(f);
  }
  return bytes;
}

std::set<std::string> all_topics() {
  std::set<std::string> out;
  for_each_topic_type([&]<class T>() { out.insert(Topic<T>::name); });
  return out;
}

struct Item {
  std::uint16_t channel;
  std::uint64_t log_ns, publish_ns;
  std::vector<std::uint8_t> data;
};

}  // namespace

struct Recorder::Impl {
  RecorderOptions opt;
  DdsConfig dds_cfg;
  mcap::Writer writer;
  std::unique_ptr<Participant> dds;
  std::vector<std::function<void(Participant&)>> subscriptions;  // one per recorded topic
  Reader<msg::SwarmState>* state_reader = nullptr;  // this participant's, when recorded
  bool said_matched = false;                        // kRecorderMatchedServer printed
  int rejoins = 0;
  std::uint64_t duplicates = 0;  // under mu: samples received again after a re-join, kept once
  std::mutex mu;
  std::condition_variable cv;
  std::atomic<bool> stopping{false};  // stop()
  std::deque<Item> queue;
  std::size_t max_queue = 0;
  std::map<std::uint16_t, std::string> channel_topic;
  std::map<std::string, std::uint64_t> written;
  std::size_t not_written = 0;                  // of a batch whose write failed
  std::map<std::string, SequenceGaps> gaps_of;  // per topic, under mu: samples sent that never came

  static mcap::WriterOptions writer_options(const RecorderOptions& o) {
    mcap::WriterOptions w;
    w.compression = o.compression == "lz4"    ? mcap::Compression::lz4
                    : o.compression == "none" ? mcap::Compression::none
                                              : mcap::Compression::zstd;
    w.chunk_size_bytes = o.chunk_bytes;
    w.profile = "";
    return w;
  }

  ~Impl() {
    if (dds) dds->close();
  }

  Impl(const DdsConfig& d, RecorderOptions o)
      : opt(std::move(o)), dds_cfg(d), writer(opt.path, writer_options(opt)) {
    const auto known = all_topics();
    for (const auto& t : opt.topics)
      if (!known.count(t))
        throw std::invalid_argument("unknown topic " + t +
                                    " (known: " + fmt::format("{}", fmt::join(known, ", ")) + ")");
    for_each_topic_type([&]<class T>() {
      const std::string topic = Topic<T>::name;
      if (!opt.topics.empty() &&
          std::find(opt.topics.begin(), opt.topics.end(), topic) == opt.topics.end())
        return;
      typename Topic<T>::PubSub type;
      const std::uint16_t schema = writer.add_schema(type.getName(), "omgidl", kIdlText);
      const std::uint16_t channel =
          writer.add_channel(schema, topic, "cdr", {{"qos_profile", Topic<T>::profile}});
      channel_topic[channel] = topic;
      written[topic] = 0;
      SequenceGaps* gaps = &gaps_of[topic];
      subscriptions.push_back([this, channel, gaps](Participant& p) {
        auto& reader = p.reader<T>(
            [this, channel, gaps](const T& sample, const fdds::SampleInfo& info) {
              Item it{channel, now_ns(), static_cast<std::uint64_t>(info.source_timestamp.to_ns()),
                      to_cdr(sample)};
              const auto& guid = info.sample_identity.writer_guid();
              SequenceGaps::WriterId writer_id;
              std::copy_n(guid.guidPrefix.value, 12, writer_id.begin());
              std::copy_n(guid.entityId.value, 4, writer_id.begin() + 12);
              std::lock_guard<std::mutex> lock(mu);
              // A re-joined reader gets the transient-local history again.
              if (!gaps->received(writer_id, info.sample_identity.sequence_number().to64long())) {
                ++duplicates;
                return;
              }
              queue.push_back(std::move(it));
              max_queue = std::max(max_queue, queue.size());
              cv.notify_one();
            },
            std::nullopt, Delivery::kArchive);
        if constexpr (std::is_same_v<T, msg::SwarmState>) state_reader = &reader;
      });
    });
    join();
    if (const long cap = udp_receive_buffer_cap(); cap > 0 && cap < kUdpSocketBufferBytes)
      spdlog::warn(
          "ddswarm-record: net.core.rmem_max is {} bytes, less than the {} the recorder asks "
          "for its UDP socket: a recorder held up for longer than that buffer lasts loses swarm "
          "states, counted as never received (sysctl -w net.core.rmem_max={} raises it)",
          cap, kUdpSocketBufferBytes, kUdpSocketBufferBytes);
  }

  /// A new participant with every reader. The old one, if any, is closed
  /// first: no callback of it runs afterwards. It never takes the
  /// shared-memory transport, so every sample comes by UDP (on 127.0.0.1
  /// unless dds names a network): a recorder sends acknowledgements to every
  /// writer it reads, and Fast DDS 2.9's shared-memory transport sleeps a
  /// third of dds.shm_health_check_s (3.3 s) when it opens a peer's port
  /// whose idle listener was just checked, holding every send of the
  /// participant. A recorder on shared memory went deaf for 3.3 s when a
  /// participant joined (the soak's hostile publisher), then lost 18 swarm
  /// states its KEEP_LAST 1 writer could not send again; one re-joined after
  /// a stop heard nothing for about 3 s in 5 stops of 6 (docs/recording.md).
  void join() {
    dds.reset();  // the old participant leaves before the new one joins
    DdsConfig cfg = dds_cfg;
    cfg.shm_transport = false;
    dds = std::make_unique<Participant>(cfg, "ddswarm-record");
    for (const auto& subscribe : subscriptions) subscribe(*dds);
  }

  /// Writes everything queued; false when the queue was empty.
  bool drain() {
    std::deque<Item> batch;
    {
      std::lock_guard<std::mutex> lock(mu);
      batch.swap(queue);
    }
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const auto& it = batch[i];
      try {
        writer.write(it.channel, it.log_ns, it.publish_ns, it.data.data(), it.data.size());
      } catch (...) {
        not_written += batch.size() - i;
        throw;
      }
      ++written[channel_topic[it.channel]];
    }
    return !batch.empty();
  }

  std::uint64_t total_written() const {
    std::uint64_t n = 0;
    for (const auto& [t, k] : written) n += k;
    return n;
  }

  RecorderCounts run(double duration_s) {
    const double end = duration_s > 0 ? wall_seconds() + duration_s : 1e300;
    try {
      LeaseWatch lease(dds_cfg.lease_duration_s, wall_seconds());
      while (!stop_requested() && !stopping && wall_seconds() < end) {
        // This loop turns at least every 100 ms plus one drain: a longer gap
        // than the lease means a stop (Ctrl-Z, SIGSTOP) or a starved machine,
        // after which a recorder could stay deaf for the rest of its run.
        if (const std::string why = lease.turn(wall_seconds()); !why.empty()) {
          spdlog::warn(
              "ddswarm-record: {}; what no writer kept meanwhile is counted as never received",
              why);
          settle_after_stop();
          join();
          ++rejoins;
          lease.restart(wall_seconds());
        }
        if (!said_matched && state_reader && state_reader->matched() > 0) {
          std::fprintf(stderr, "%s\n", kRecorderMatchedServer);
          said_matched = true;
        }
        {
          std::unique_lock<std::mutex> lock(mu);
          cv.wait_for(lock, std::chrono::milliseconds(100),
                      [&] { return !queue.empty() || stopping; });
        }
        drain();
      }
      // Stop listening, then write what arrived before the stop: nothing received is lost.
      if (dds) dds->close();
      drain();
      writer.close();
    } catch (const std::runtime_error& e) {
      // An I/O failure (disk full, device gone): say exactly what the file
      // holds and what was received but could not be written.
      if (dds) dds->close();
      std::size_t unwritten;
      {
        std::lock_guard<std::mutex> lock(mu);
        unwritten = queue.size() + not_written;
      }
      try {
        writer.close();
      } catch (const std::exception&) {
      }
      throw std::runtime_error(
          fmt::format("{}; recording stopped: {} messages were handed to the file, {} more "
                      "received were not written; "
                      "{} reads up to its last complete chunk (ddswarm-record info)",
                      e.what(), total_written(), unwritten, opt.path));
    }
    RecorderCounts c;
    c.messages = written;
    c.bytes = writer.bytes_written();
    c.max_queue = max_queue;
    c.rejoins = rejoins;
    c.duplicates = duplicates;
    for (const auto& [topic, gaps] : gaps_of)
      if (gaps.missed()) c.missed[topic] = gaps.missed();
    return c;
  }
};

Recorder::Recorder(const DdsConfig& dds, RecorderOptions options)
    : impl_(std::make_unique<Impl>(dds, std::move(options))) {}
Recorder::~Recorder() = default;
RecorderCounts Recorder::run(double duration_s) { return impl_->run(duration_s); }
void Recorder::stop() {
  impl_->stopping = true;
  impl_->cv.notify_all();
}

std::string describe_recording(const std::string& path, bool messages) {
  mcap::Reader r(path);
  const auto& st = r.statistics();
  std::string out = fmt::format("{}: {} messages on {} channels ({})\n", path, st.message_count,
                                r.channels().size(), r.how_read().describe());
  for (const auto& [id, ch] : r.channels()) {
    auto it = st.channel_message_counts.find(id);
    const auto& schema = r.schemas().count(ch.schema_id) ? r.schemas().at(ch.schema_id).name : "";
    out += fmt::format("  {:<24} {:>9} messages  {}\n", ch.topic,
                       it == st.channel_message_counts.end() ? 0 : it->second, schema);
  }
  const double start = st.message_start_time_ns * 1e-9, end = st.message_end_time_ns * 1e-9;
  out += fmt::format("start {:.3f} s, end {:.3f} s (unix time), duration {:.3f} s\n", start, end,
                     st.message_count ? end - start : 0.0);
  if (messages) {
    r.for_each_message([&](const mcap::MessageView& m) {
      std::uint64_t h = 1469598103934665603ULL;
      for (auto b : m.data) h = (h ^ b) * 1099511628211ULL;
      const auto* ch = r.channel(m.channel_id);
      out +=
          fmt::format("{} {} {} {:016x}\n", m.log_time_ns, ch ? ch->topic : "?", m.data.size(), h);
    });
  }
  return out;
}

double replay_rate(double asked, double peak_per_s) {
  if (!(asked > 1) || !(peak_per_s * asked > kReplayMaxSamplesPerS)) return asked;
  return std::max(1.0, kReplayMaxSamplesPerS / peak_per_s);
}

std::uint64_t replay(const DdsConfig& dds, const std::string& path, double rate, bool loop,
                     const std::vector<std::string>& topics) {
  return Replay(dds, path, rate, loop, topics).run();
}

Replay::Replay(DdsConfig dds, std::string path, double rate, bool loop,
               std::vector<std::string> topics)
    : dds_(std::move(dds)),
      path_(std::move(path)),
      rate_(rate),
      loop_(loop),
      topics_(std::move(topics)) {}

bool Replay::stopping() const { return stop_ || stop_requested(); }

std::uint64_t Replay::run() {
  const DdsConfig& dds_cfg = dds_;
  const std::string& path = path_;
  double rate = rate_;
  const bool loop = loop_;
  const std::vector<std::string>& topics = topics_;
  if (!(rate > 0)) throw std::invalid_argument("--rate must be > 0");
  mcap::Reader r(path);
  Participant dds(dds_cfg, "ddswarm-replay");
  // A live server on this domain would take the recording's missions and
  // commands as its own, and its agents the recorded scene: refuse.
  std::mutex mu;
  std::optional<std::uint64_t> live_server;
  auto& scenes = dds.reader<msg::Scene>([&](const msg::Scene& s, const fdds::SampleInfo&) {
    std::lock_guard<std::mutex> lock(mu);
    live_server = s.server_instance();
  });
  // One publisher per recorded channel whose topic ddswarm knows.
  std::map<std::uint16_t, std::function<void(std::span<const std::uint8_t>)>> publish;
  // Channels whose readers may take samples by data-sharing: those whose
  // profile does not read them VOLATILE (with the shipped profiles, the
  // transient-local ones: the swarm state, scene, status, missions, acks).
  std::set<std::uint16_t> shared;
  for (const auto& [id, ch] : r.channels()) {
    if (!topics.empty() && std::find(topics.begin(), topics.end(), ch.topic) == topics.end())
      continue;
    for_each_topic_type(
        [&, id = id, &ch = ch]<class T>() {  // clang 14 cannot capture a structured binding
          if (ch.topic != Topic<T>::name) return;
          auto w = std::make_shared<Writer<T>>(dds.writer<T>());
          if (!dds.profile_never_shares<T>()) shared.insert(id);
          // A recording made before scans carried elevations is replayed as
          // this build writes scans (every elevation 0).
          const ScanLayout layout = channel_scan_layout(r, ch);
          publish[id] = [w, layout](std::span<const std::uint8_t> bytes) {
            T sample;
            if (from_cdr(bytes, sample, layout)) w->write(sample);
          };
        });
  }
  // Let readers match before the first sample (volatile samples sent earlier
  // are lost), and a live server's scene (transient local) arrive.
  wait_for_stop(std::chrono::milliseconds(1500));
  dds.remove(scenes);
  if (live_server)
    throw std::runtime_error(
        fmt::format("a live server (instance {:016x}) is on DDS domain {}: its swarm would fly the "
                    "recording's missions and commands; replay on another domain (--domain)",
                    *live_server, dds_cfg.domain_id));
  if (rate > 1) {  // faster than recorded: held by the busiest such topic's busiest second
    std::map<std::pair<std::uint16_t, std::uint64_t>, std::uint64_t> per_second;
    std::uint64_t peak = 0;
    r.for_each_message([&](const mcap::MessageView& m) {
      if (shared.count(m.channel_id))
        peak = std::max(peak, ++per_second[{m.channel_id, m.log_time_ns / 1'000'000'000}]);
    });
    const double asked = rate;
    rate = replay_rate(asked, static_cast<double>(peak));
    if (rate != asked)
      std::fprintf(stderr,
                   "ddswarm-replay: --rate %g held to %.3g: at %g one topic would be written "
                   "%.0f times a second, and Fast DDS 2.9.1 may crash a reader that joins a "
                   "writer that fast (docs/dds.md)\n",
                   asked, rate, asked, static_cast<double>(peak) * asked);
  }
  std::uint64_t sent = 0;
  do {
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t first = 0;
    bool have_first = false;
    r.for_each_message([&](const mcap::MessageView& m) {
      if (stopping()) return;
      auto it = publish.find(m.channel_id);
      if (it == publish.end()) return;
      if (!have_first) {
        first = m.log_time_ns;
        have_first = true;
      }
      const double offset_s = (m.log_time_ns - first) * 1e-9 / rate;
      std::this_thread::sleep_until(start +
                                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>(offset_s)));
      it->second(m.data);
      ++sent;
    });
  } while (loop && !stopping());
  wait_for_stop(std::chrono::milliseconds(500));  // let reliable samples go out
  return sent;
}

}  // namespace ddswarm::gs
