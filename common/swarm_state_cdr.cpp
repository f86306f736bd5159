#include "common/swarm_state_cdr.hpp"

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "common/topics.hpp"

namespace ddswarm {
namespace {

/// XCDR1 as Fast CDR reads it: each primitive aligned to its size, counted
/// from the first byte after the encapsulation header; `ok` turns false at
/// the first read past the end and stays false.
class CdrIn {
 public:
  CdrIn(const std::uint8_t* body, std::size_t size, bool swap) : p_(body), n_(size), swap_(swap) {}
  bool ok() const { return ok_; }

  template <class T>
  void get(T& v) {
    static_assert(std::is_arithmetic_v<T>);
    align(sizeof(T));
    if (!take(sizeof(T))) return;
    std::memcpy(&v, p_ + pos_ - sizeof(T), sizeof(T));
    if constexpr (sizeof(T) > 1)
      if (swap_) v = swapped(v);
  }
  /// n values of T, contiguous after one alignment (a C array or a sequence's elements).
  template <class T>
  void get_array(T* v, std::size_t n) {
    if (n == 0) return;
    align(sizeof(T));
    if (!take(sizeof(T) * n)) return;
    std::memcpy(v, p_ + pos_ - sizeof(T) * n, sizeof(T) * n);
    if constexpr (sizeof(T) > 1)
      if (swap_)
        for (std::size_t k = 0; k < n; ++k) v[k] = swapped(v[k]);
  }
  /// A sequence's length, refused above its IDL bound.
  std::uint32_t length(std::uint32_t bound) {
    std::uint32_t len = 0;
    get(len);
    if (len > bound) ok_ = false;
    return ok_ ? len : 0;
  }
  /// A string as Fast CDR reads it (length with the terminator, then the
  /// bytes), assigned as the generated code does: up to its first NUL, and
  /// at most the fixed string's size. No copy on the heap: this runs for
  /// every recent command in every agent every tick.
  template <std::size_t N>
  void string(eprosima::fastrtps::fixed_string<N>& out) {
    std::uint32_t len = 0;
    get(len);
    out = "";
    if (!ok_ || len == 0 || !take(len)) return;
    const char* s = reinterpret_cast<const char*>(p_ + pos_ - len);
    out.assign(s, strnlen(s, len));
  }

 private:
  void align(std::size_t a) { pos_ += (a - pos_ % a) % a; }
  bool take(std::size_t bytes) {
    if (!ok_ || pos_ > n_ || n_ - pos_ < bytes) return ok_ = false;
    pos_ += bytes;
    return true;
  }
  template <class T>
  static T swapped(T v) {
    static_assert(sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
    using U = std::conditional_t<sizeof(T) == 2, std::uint16_t,
                                 std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>;
    U u;
    std::memcpy(&u, &v, sizeof u);
    if constexpr (sizeof(T) == 2)
      u = __builtin_bswap16(u);
    else if constexpr (sizeof(T) == 4)
      u = __builtin_bswap32(u);
    else
      u = __builtin_bswap64(u);
    std::memcpy(&v, &u, sizeof u);
    return v;
  }

  const std::uint8_t* p_;
  std::size_t n_, pos_ = 0;
  bool swap_, ok_ = true;
};

void read(CdrIn& in, msg::Vec3& v) {
  in.get(v.x());
  in.get(v.y());
  in.get(v.z());
}

void read(CdrIn& in, msg::Quat& q) {
  in.get(q.w());
  in.get(q.x());
  in.get(q.y());
  in.get(q.z());
}

void read(CdrIn& in, msg::DroneState& d) {
  in.get(d.drone_id());
  in.get(d.tick());
  in.get(d.sim_time_s());
  read(in, d.position());
  read(in, d.orientation());
  read(in, d.velocity());
  read(in, d.angular_velocity());
  in.get_array(d.motor_speed_rad_s().data(), d.motor_speed_rad_s().size());
  in.get(d.collisions_obstacle());
  in.get(d.collisions_drone());
  in.get(d.collisions_ground());
  in.get(d.flags());
  in.get(d.phase());
  in.get(d.command_age_s());
}

template <class T>
void read_sequence(CdrIn& in, std::vector<T>& v, std::uint32_t bound) {
  v.resize(in.length(bound));
  in.get_array(v.data(), v.size());
}

void read(CdrIn& in, msg::DistanceScan& s, ScanLayout layout) {
  in.get(s.drone_id());
  in.get(s.tick());
  in.get(s.sim_time_s());
  in.get(s.max_range_m());
  if (layout == ScanLayout::kRing64) {
    read_sequence(in, s.angle_body_rad(), 64);
    s.elevation_body_rad().assign(s.angle_body_rad().size(), 0.0f);
    read_sequence(in, s.range_m(), 64);
    read_sequence(in, s.hit(), 64);
    return;
  }
  read_sequence(in, s.angle_body_rad(), 256);
  read_sequence(in, s.elevation_body_rad(), 256);
  read_sequence(in, s.range_m(), 256);
  read_sequence(in, s.hit(), 256);
}

void read(CdrIn& in, msg::MissionCommand& c) {
  in.get(c.seq());
  in.get(c.type());
  in.get(c.target());
  read(in, c.velocity());
  in.get(c.duration_s());
  in.get(c.value());
  in.get(c.leader_id());
  in.get(c.epsilon_m());
  in.string(c.issuer());
  in.get(c.issuer_instance());
  in.get(c.server_instance());
  in.get(c.apply_tick());
}

void read(CdrIn& in, msg::Beacon& b) {
  in.get(b.drone_id());
  in.get(b.tick());
  in.get(b.stamp_s());
  read(in, b.position());
  read(in, b.velocity());
  read(in, b.true_position());
}

template <class T, class... Layout>
void read_structs(CdrIn& in, std::vector<T>& v, std::uint32_t bound, Layout... layout) {
  v.resize(in.length(bound));
  for (auto& e : v) {
    if (!in.ok()) return;
    read(in, e, layout...);
  }
}

/// The encapsulation header's byte order, or false for a header Fast CDR refuses.
bool encapsulation(const std::uint8_t* data, std::size_t size, bool& swap) {
  if (size < 4) return false;
  // Encapsulation: byte 0 is zero; byte 1 bit 0 is the byte order (1: little
  // endian), bit 1 the parameter-list flag. Fast CDR refuses anything else
  // there, and reads and ignores the options (bytes 2-3).
  if (data[0] != 0 || (data[1] & ~0x3) != 0) return false;
  const bool little = (data[1] & 0x1) != 0;
  swap = little != (std::endian::native == std::endian::little);
  return true;
}

}  // namespace

bool decode_swarm_state(const std::uint8_t* data, std::size_t size, msg::SwarmState& out,
                        ScanLayout layout) {
  bool swap = false;
  if (!encapsulation(data, size, swap)) return false;
  CdrIn in(data + 4, size - 4, swap);
  in.get(out.tick());
  in.get(out.sim_time_s());
  read_structs(in, out.drones(), 1024);
  read_structs(in, out.scans(), 1024, layout);
  read_structs(in, out.recent_commands(), 8);
  read_structs(in, out.beacons(), 1024);
  return in.ok();
}

bool decode_distance_scan(const std::uint8_t* data, std::size_t size, msg::DistanceScan& out,
                          ScanLayout layout) {
  bool swap = false;
  if (!encapsulation(data, size, swap)) return false;
  CdrIn in(data + 4, size - 4, swap);
  read(in, out, layout);
  return in.ok();
}

ScanLayout scan_layout_of(std::string_view schema_idl) {
  const auto at = schema_idl.find("struct DistanceScan");
  if (at == std::string_view::npos) return ScanLayout::kCurrent;
  const std::string_view body = schema_idl.substr(at, schema_idl.find("};", at) - at);
  return body.find("elevation_body_rad;") == std::string_view::npos ? ScanLayout::kRing64
                                                                    : ScanLayout::kCurrent;
}

std::vector<std::uint8_t> encode_swarm_state(const msg::SwarmState& s, bool big_endian,
                                             ScanLayout layout) {
  msg::SwarmStatePubSubType type;
  eprosima::fastrtps::rtps::SerializedPayload_t p(
      type.getSerializedSizeProvider(const_cast<msg::SwarmState*>(&s))());
  eprosima::fastcdr::FastBuffer buf(reinterpret_cast<char*>(p.data), p.max_size);
  eprosima::fastcdr::Cdr cdr(buf,
                             big_endian ? eprosima::fastcdr::Cdr::BIG_ENDIANNESS
                                        : eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS,
                             eprosima::fastcdr::Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  if (layout == ScanLayout::kCurrent) {
    s.serialize(cdr);
  } else {  // SwarmState.idl's order, each scan without its elevations
    cdr << s.tick() << s.sim_time_s() << static_cast<std::uint32_t>(s.drones().size());
    for (const auto& d : s.drones()) d.serialize(cdr);
    cdr << static_cast<std::uint32_t>(s.scans().size());
    for (const auto& sc : s.scans())
      cdr << sc.drone_id() << sc.tick() << sc.sim_time_s() << sc.max_range_m()
          << sc.angle_body_rad() << sc.range_m() << sc.hit();
    cdr << static_cast<std::uint32_t>(s.recent_commands().size());
    for (const auto& c : s.recent_commands()) c.serialize(cdr);
    cdr << static_cast<std::uint32_t>(s.beacons().size());
    for (const auto& b : s.beacons()) b.serialize(cdr);
  }
  return {p.data, p.data + cdr.getSerializedDataLength()};
}

}  // namespace ddswarm

namespace ddswarm {

template <>
bool SafePubSub<msg::SwarmStatePubSubType>::deserialize(
    eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) {
  if (decode_swarm_state(payload->data, payload->length, *static_cast<msg::SwarmState*>(data))) {
    payload->encapsulation = (payload->data[1] & 0x1) ? CDR_LE : CDR_BE;
    return true;
  }
  malformed_samples().fetch_add(1, std::memory_order_relaxed);
  return false;
}

}  // namespace ddswarm
