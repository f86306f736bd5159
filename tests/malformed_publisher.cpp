// A test helper that puts malformed samples on the wire, as a broken or
// hostile participant could: for --attack wall seconds it publishes, at 50 Hz,
//   - VelocityCommands for drone --id whose motors_on byte is 2 (CDR allows
//     only 0 or 1), and
//   - AgentStatus heartbeats whose server_lost byte is 2,
// each otherwise well formed and carrying a velocity that would visibly move
// the drone if it were applied. Fast CDR refuses such a sample by throwing;
// a reader that lets that exception escape dies. The samples are serialised by
// the generated type support, then one byte is changed; the writers copy the
// QoS and partitions of the project's own writers, so they match as any
// participant's would. Exits 0 once it has published everything.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <thread>

#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

/// The generated type support of T, with byte `offset` of every serialised
/// payload (encapsulation included) replaced by `value`.
template <class T>
class Corrupting : public Topic<T>::PubSub {
 public:
  Corrupting(std::size_t offset, std::uint8_t value) : offset_(offset), value_(value) {}
  bool serialize(void* data, rtps::SerializedPayload_t* payload) override {
    if (!Topic<T>::PubSub::serialize(data, payload)) return false;
    if (offset_ < payload->length) payload->data[offset_] = value_;
    return true;
  }

 private:
  std::size_t offset_;
  std::uint8_t value_;
};

/// Where the byte of `field` lies in a payload: the first byte that differs
/// between a sample with the bool false and one with it true.
template <class T>
std::size_t bool_offset(void (T::*set)(bool)) {
  typename Topic<T>::PubSub type;
  T a, b;
  (a.*set)(false);
  (b.*set)(true);
  rtps::SerializedPayload_t pa(type.getSerializedSizeProvider(&a)()),
      pb(type.getSerializedSizeProvider(&b)());
  if (!type.serialize(&a, &pa) || !type.serialize(&b, &pb))
    throw std::runtime_error("cannot serialise");
  for (std::size_t i = 0; i < pa.length && i < pb.length; ++i)
    if (pa.data[i] != pb.data[i]) return i;
  throw std::runtime_error("bool field not found in the payload");
}

/// A writer on `topic_name` with the QoS and partitions of `like`, whose
/// samples are corrupted at `offset`.
template <class T>
fdds::DataWriter* corrupt_writer(fdds::DomainParticipant* dp, fdds::DataWriter* like,
                                 std::size_t offset) {
  fdds::TypeSupport ts(new Corrupting<T>(offset, 2));
  if (ts.register_type(dp) != ReturnCode_t::RETCODE_OK)
    throw std::runtime_error("cannot register type");
  auto* topic = dp->create_topic(Topic<T>::name, ts.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  auto* pub = topic ? dp->create_publisher(like->get_publisher()->get_qos()) : nullptr;
  auto* w = pub ? pub->create_datawriter(topic, like->get_qos()) : nullptr;
  if (!w)
    throw std::runtime_error(std::string("cannot create a corrupting writer on ") + Topic<T>::name);
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("malformed_publisher", [&]() -> int {
    CLI::App app{"publish malformed VelocityCommand and AgentStatus samples"};
    DdsConfig dds;
    int id = 0;
    double attack_s = 3.0;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--id", id, "the drone the commands address");
    app.add_option("--attack", attack_s, "wall seconds of malformed traffic");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();

    // The project's own writers, for their QoS and partitions (never written).
    dds = one_shot(dds);  // a few seconds' attack: kOneShotLeaseS says why
    Participant model(dds, "malformed_publisher_model");
    auto w_cmd = model.writer<msg::VelocityCommand>();
    auto w_hb = model.writer<msg::AgentStatus>();
    // A second participant (localhost-only like every Participant) registers
    // the corrupting type support under the real type names.
    Participant p(dds, "malformed_publisher");
    auto* cmd = corrupt_writer<msg::VelocityCommand>(p.raw(), w_cmd.raw(),
                                                     bool_offset(&msg::VelocityCommand::motors_on));
    auto* hb = corrupt_writer<msg::AgentStatus>(p.raw(), w_hb.raw(),
                                                bool_offset(&msg::AgentStatus::server_lost));

    // Wait for the server's readers to match.
    const double t0 = wall_seconds();
    fdds::PublicationMatchedStatus st;
    while (!stop_requested() && wall_seconds() - t0 < 10) {
      cmd->get_publication_matched_status(st);
      if (st.current_count > 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (st.current_count == 0) {
      std::fprintf(stderr,
                   "malformed_publisher: no reader matched the command writer within 10 s\n");
      return 1;
    }
    int sent = 0;
    const double start = wall_seconds();
    for (std::uint64_t k = 0; !stop_requested() && wall_seconds() - start < attack_s; ++k) {
      msg::VelocityCommand c;
      c.drone_id(static_cast<std::uint16_t>(id));
      c.tick(k);
      c.velocity(to_msg(Eigen::Vector3d(3.0, 0, 2.0)));
      c.motors_on(true);
      c.agent_instance(0xbadbadbadbad0003ULL);
      msg::AgentStatus a;
      a.drone_id(static_cast<std::uint16_t>(id));
      a.agent_instance(0xbadbadbadbad0003ULL);
      a.server_lost(true);
      sent += cmd->write(&c) ? 1 : 0;
      sent += hb->write(&a) ? 1 : 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::printf("malformed_publisher: %d malformed samples published\n", sent);
    return 0;
  });
}
