#pragma once
// DDS plumbing: one Participant per process, typed writers and readers.
//
// The participant's transports come from DdsConfig (localhost-only unless the
// user opts in); QoS comes from the XML profiles named in common/topics.hpp.
#include <atomic>
#include <cstdint>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "common/process.hpp"
#include "common/topics.hpp"

namespace ddswarm {

namespace fdds = eprosima::fastdds::dds;

/// A DDS failure during setup (what() names what failed).
class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Records a write that Fast DDS threw out of, and returns false. Fast DDS
/// 2.9 throws through DataWriter::write when a shared-memory lock of a
/// reader's stays held past its timeout ("Interprocess mutex timeout when
/// locking. Possible deadlock: owner died without unlocking?"): a process
/// SIGKILLed while it held it. The sample is lost for that reader; the writer
/// goes on. Logged at the first failure and at every power of two after it.
bool write_threw(fdds::DataWriter* w, const std::exception& e);
/// How many writes have thrown in this process (write_threw).
std::uint64_t write_throws();

/// Records a sample whose handler threw on a Fast DDS thread (where the
/// exception would end the process in std::terminate): the sample is dropped
/// and the reader goes on. Logged at the first and at every power of two;
/// handlers should refuse what they cannot apply themselves (and count it),
/// so this is the last guard, not the rule.
void handler_threw(fdds::DataReader* r, const std::exception& e);
/// How many samples' handlers have thrown in this process (handler_threw).
std::uint64_t handler_throws();

/// A process's last step, the return value of its main(): ends the process
/// with code at once when it has no Fast DDS participant left, after flushing
/// spdlog, Fast DDS's log and stdio. Fast DDS 2.9's DomainParticipantFactory
/// sleeps 100 ms in its static destructor, before it stops its log thread;
/// every ddswarm process would pay that as it stops, about half of a Table 1
/// run's teardown. A participant still open at this point returns code for a
/// normal exit, in which that destructor deletes it and tells its peers.
/// Sanitizer builds return code too: their checks run at exit.
int end_process(int code);

template <class T>
class Writer {
 public:
  explicit Writer(fdds::DataWriter* w) : w_(w) {}
  /// Returns false when DDS refused the sample or threw (write_threw).
  bool write(const T& sample) {
    try {
      return w_->write(const_cast<T*>(&sample));
    } catch (const std::exception& e) {
      return write_threw(w_, e);
    }
  }
  /// Number of matched readers.
  int matched() const {
    fdds::PublicationMatchedStatus s;
    w_->get_publication_matched_status(s);
    return s.current_count;
  }
  fdds::DataWriter* raw() const { return w_; }

 private:
  fdds::DataWriter* w_;
};

/// How a reader receives its topic. kLatest reads it best-effort whatever
/// its profile says: no acknowledgements, a lost sample is superseded by the
/// next. Only for the per-tick streams (kPerTickStream), and only from a
/// reliable writer's point of view: writers keep their profile, so every
/// reliable reader of the same writer still gets every sample.
/// kArchive is for readers that must keep every sample (the recorder): the
/// profile's reliability, but by the transport, never by data-sharing. A
/// data-sharing writer with a KEEP_LAST history reuses a sample's slot in its
/// pool `depth` samples later, even if a reader has not read it yet (under
/// load, a recorder lost 1-4 of 300 swarm states replayed at 240/s in 5 of
/// 10 runs); the transport queues the sample in the reader's own port instead. (Fast DDS
/// 2.9.1 reports such a loss in the sample-lost status only sometimes: in
/// one of six runs of Participant.ArchiveReaderKeepsEverySampleThroughAStall;
/// count gaps in the writer's sequence numbers instead, as the recorder does.)
enum class Delivery { kProfile, kLatest, kArchive };

/// Called from a Fast DDS thread for every valid sample.
template <class T>
using SampleHandler = std::function<void(const T&, const fdds::SampleInfo&)>;

template <class T>
class Reader : public fdds::DataReaderListener {
 public:
  explicit Reader(SampleHandler<T> h) : handler_(std::move(h)) {}
  void attach(fdds::DataReader* r) { r_ = r; }
  fdds::DataReader* raw() const { return r_; }
  int matched() const { return matched_.load(); }
  /// wall_seconds() when the matched writers last went from none to some
  /// (-1e9 before the first match): a writer back after its participant was
  /// dropped counts from then.
  double matched_since() const { return matched_since_.load(); }

  void on_data_available(fdds::DataReader* reader) override {
    // One sample object, reused: deserializing into it keeps its sequences'
    // capacity, so a whole-swarm sample costs no allocation per drone per tick.
    std::lock_guard<std::mutex> lock(sample_mu_);
    fdds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || !handler_) continue;
      try {
        handler_(sample_, info);
      } catch (const std::exception& e) {
        handler_threw(reader, e);
      }
    }
  }
  void on_subscription_matched(fdds::DataReader*,
                               const fdds::SubscriptionMatchedStatus& s) override {
    if (s.current_count > 0 && matched_.load() == 0) matched_since_ = wall_seconds();
    matched_ = s.current_count;
  }

 private:
  SampleHandler<T> handler_;
  fdds::DataReader* r_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<double> matched_since_{-1e9};
  std::mutex sample_mu_;  // transports' receive threads may deliver at once
  T sample_;
};

/// The GUID prefix of a process's participant number n (n >= 1; the first,
/// number 0, has Fast DDS's own): the first's host and process bytes, n in
/// the last three bytes, where Fast DDS's prefixes hold zeros (the
/// participant id's upper bytes), so it is unique in the process and on the
/// host, and Fast DDS still sees one host and one process.
eprosima::fastrtps::rtps::GuidPrefix_t incarnation_prefix(
    const eprosima::fastrtps::rtps::GuidPrefix_t& first, std::uint32_t n);

/// Whether a process on this host holds the metatraffic port of
/// participant_id in domain_id on 127.0.0.1, as a live participant with that
/// id does.
bool participant_id_taken_here(int domain_id, int participant_id);

class PeerWatch;

/// A live remote participant this one discovered (Participant::peers_named).
struct RemotePeer {
  eprosima::fastrtps::rtps::GuidPrefix_t prefix;
  double announced_s;  ///< since it announced itself (its discovery data came)
  /// Under DDS Security, how long after its announcement its authentication
  /// handshake with this participant passed; < 0 while it has not (pending,
  /// or refused), and always without DDS Security.
  double authenticated_after_s;
};

class Participant {
 public:
  /// Joins the domain; throws DdsError naming what failed. name shows in tools.
  Participant(const DdsConfig& cfg, const std::string& name);
  ~Participant();
  /// Deletes every reader and writer, waiting for running callbacks, so no
  /// handler runs afterwards. Owners whose handlers touch their own members
  /// must call this first in their destructor (members die before the
  /// Participant otherwise). Idempotent.
  void close();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  /// A writer in the default partition, or in partition (e.g. drone_partition(k)).
  template <class T>
  Writer<T> writer(const std::string& partition = "") {
    auto* topic = topic_for<T>();
    auto* pub = publisher_for(partition);
    fdds::DataWriter* w = nullptr;
    fdds::DataWriterQos q;  // a missing profile leaves w null
    if (pub->get_datawriter_qos_from_profile(Topic<T>::profile, q) == ReturnCode_t::RETCODE_OK) {
      // Never a reliable VOLATILE writer, even from a user's profile file:
      // Fast DDS 2.9.1 can deadlock one when a reader leaves (docs/dds.md).
      // Readers keep their durability, so nothing they receive changes.
      if (q.reliability().kind == fdds::RELIABLE_RELIABILITY_QOS &&
          q.durability().kind == fdds::VOLATILE_DURABILITY_QOS)
        q.durability().kind = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
      if (!shared_memory_) q.data_sharing().off();
      w = pub->create_datawriter(topic, q);
    }
    if (!w)
      throw DdsError(std::string("cannot create writer for ") + Topic<T>::name +
                     refused_hint(partition));
    return Writer<T>(w);
  }

  /// Creates a reader whose handler runs on a Fast DDS thread for each sample.
  /// partition may be a pattern ("drone/*"); by default a per-drone topic
  /// (kPerDronePartition) is read from every drone's partition when secure.
  template <class T>
  Reader<T>& reader(SampleHandler<T> handler,
                    std::optional<std::string> partition_opt = std::nullopt,
                    Delivery delivery = Delivery::kProfile) {
    if (delivery == Delivery::kLatest && !kPerTickStream<T>)
      throw DdsError(std::string("only the per-tick streams may be read best-effort, not ") +
                     Topic<T>::name);
    const std::string partition =
        partition_opt.value_or(secure_ && kPerDronePartition<T> ? "drone/*" : "");
    auto* topic = topic_for<T>();
    auto listener = std::make_unique<Reader<T>>(std::move(handler));
    auto* sub = subscriber_for(partition);
    fdds::DataReader* r = nullptr;
    fdds::DataReaderQos q;
    if (sub->get_datareader_qos_from_profile(Topic<T>::profile, q) == ReturnCode_t::RETCODE_OK) {
      if (delivery == Delivery::kLatest) q.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
      // Never a VOLATILE reader by data-sharing, even from a user's profile
      // file: Fast DDS 2.9.1 aborts the process when one matches a writer
      // that writes meanwhile (ReaderPool.hpp:141, docs/dds.md). The swarm
      // state's readers are transient-local instead (config/dds_profiles.xml).
      if (!shared_memory_ || delivery == Delivery::kArchive || never_shares(q))
        q.data_sharing().off();
      // A reader that may take samples by data-sharing gets a subscriber of
      // its own, so that it alone can leave every writer before it is
      // deleted (delete_reader()).
      if (q.data_sharing().kind() != fdds::OFF && bounded(topic)) sub = own_subscriber(partition);
      r = sub->create_datareader(topic, q, listener.get());
    }
    if (!r)
      throw DdsError(std::string("cannot create reader for ") + Topic<T>::name +
                     refused_hint(partition));
    listener->attach(r);
    auto& ref = *listener;
    listeners_.push_back(std::move(listener));
    return ref;
  }

  /// Whether T's profile reads VOLATILE, so that reader() and every other
  /// process's reader of T never take its samples by data-sharing, the
  /// delivery a writer's pace can put at risk (docs/dds.md).
  template <class T>
  bool profile_never_shares() {
    fdds::DataReaderQos q;
    return subscriber_for("")->get_datareader_qos_from_profile(Topic<T>::profile, q) ==
               ReturnCode_t::RETCODE_OK &&
           never_shares(q);
  }

  /// Deletes a reader made by reader() (waiting for a running callback):
  /// its handler never runs again and its samples stop flowing to us.
  template <class T>
  void remove(Reader<T>& r) {
    if (closed_ || !r.raw()) return;
    delete_reader(r.raw());
    r.attach(nullptr);
  }

  fdds::DomainParticipant* raw() const { return participant_; }
  /// True when DDS Security is on (DdsConfig::security_dir).
  bool secure() const { return secure_; }
  /// The live remote participants named `name` (kServerParticipantName: the
  /// servers), as discovery announced them, oldest first. An agent whose old
  /// server went silent learns so that a new one exists even when what the
  /// new one sends it never arrives (docs/faults.md); under DDS Security, that
  /// a server's handshake with it is still pending, as Fast DDS 2.9 sometimes
  /// leaves one for good (docs/security.md).
  std::vector<RemotePeer> peers_named(const std::string& name) const;
  /// True when this participant uses shared memory (the transport and
  /// data-sharing delivery): dds.shared_memory, and neither DDS Security nor
  /// the TSan build.
  bool shared_memory() const { return shared_memory_; }
  /// false: no agent discovers this participant (DdsConfig::meets_agents, and
  /// an id above the agents' was free); what it knows of agents comes from
  /// the server.
  bool meets_agents() const { return meets_agents_; }

 private:
  fdds::Publisher* publisher_for(const std::string& partition);
  fdds::Subscriber* subscriber_for(const std::string& partition);
  /// A new subscriber in partition (none: the default partition); throws DdsError.
  fdds::Subscriber* new_subscriber(const std::string& partition);
  /// A new subscriber in partition, for one reader that may take samples by
  /// data-sharing; deleted with it.
  fdds::Subscriber* own_subscriber(const std::string& partition);
  /// Whether topic's type has a bound, as data-sharing needs.
  bool bounded(fdds::Topic* topic) const;
  /// Deletes a reader, and the subscriber it has to itself, having first
  /// taken that subscriber out of every writer's partition (leave_writers()).
  void delete_reader(fdds::DataReader* r);
  /// Moves a reader's own subscriber to a partition no writer uses: Fast DDS
  /// unmatches every writer at once, on this thread, while the reader lives.
  /// Debian's Fast DDS 2.9.1 spins for ever in a data-sharing reader's thread
  /// that holds a sample when the reader is marked dead (its backport of
  /// CVE-2023-39534), and deleting the reader then waits for that thread for
  /// ever; a reader with no writer's pool left holds no sample (docs/dds.md).
  static void leave_writers(fdds::Subscriber* s);
  /// No VOLATILE reader by data-sharing (reader(), profile_never_shares()).
  static bool never_shares(const fdds::DataReaderQos& q) {
    return q.durability().kind == fdds::VOLATILE_DURABILITY_QOS;
  }
  /// Under DDS Security, why creating an endpoint may fail; empty otherwise.
  std::string refused_hint(const std::string& partition) const;
  template <class T>
  fdds::Topic* topic_for() {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = topics_.find(Topic<T>::name);
    if (it != topics_.end()) return it->second;
    fdds::TypeSupport ts(new typename Topic<T>::PubSub());
    if (ts.register_type(participant_) != ReturnCode_t::RETCODE_OK &&
        !participant_->find_type(ts.get_type_name()))
      throw DdsError(std::string("cannot register type for ") + Topic<T>::name);
    auto* t =
        participant_->create_topic(Topic<T>::name, ts.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
    if (!t) throw DdsError(std::string("cannot create topic ") + Topic<T>::name);
    topics_[Topic<T>::name] = t;
    return t;
  }

  std::unique_ptr<PeerWatch> peer_watch_;  // outlives participant_
  fdds::DomainParticipant* participant_ = nullptr;
  bool closed_ = false;
  bool secure_ = false;
  // Whether this participant uses shared memory at all: without the transport
  // (dds.shared_memory false, DDS Security, the TSan build) Fast DDS's
  // data-sharing delivery, which also goes through /dev/shm, is off too.
  bool shared_memory_ = false;
  bool meets_agents_ = true;
  std::string role_;
  fdds::Publisher* publisher_ = nullptr;
  fdds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, fdds::Publisher*> partition_publishers_;    // guarded by mu_
  std::map<std::string, fdds::Subscriber*> partition_subscribers_;  // guarded by mu_
  std::set<fdds::Subscriber*> own_subscribers_;                     // guarded by mu_
  std::mutex mu_;
  std::map<std::string, fdds::Topic*> topics_;
  std::vector<std::unique_ptr<fdds::DataReaderListener>> listeners_;
};

}  // namespace ddswarm
