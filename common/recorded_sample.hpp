#pragma once
// A recorded sample back from its bytes, for every reader of recordings
// (ddswarm-replay, the web view's replay, Python's ddswarm.Recording): one
// decoder per type, and scans as the recording's schema lays them out.
#include <cstdint>
#include <cstring>
#include <exception>
#include <span>
#include <type_traits>

#include "common/mcap/mcap_reader.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"

namespace ddswarm {

/// The scan layout a channel's schema describes (scan_layout_of); kCurrent
/// for a channel without one.
inline ScanLayout channel_scan_layout(const mcap::Reader& r, const mcap::Channel& ch) {
  const auto schema = r.schemas().find(ch.schema_id);
  return scan_layout_of(schema == r.schemas().end() ? "" : schema->second.data);
}

/// Deserialises one recorded CDR payload (encapsulation header included).
/// False for bytes the type's decoder refuses, truncated ones included.
template <class T>
bool from_cdr(std::span<const std::uint8_t> bytes, T& sample,
              ScanLayout layout = ScanLayout::kCurrent) {
  if constexpr (std::is_same_v<T, msg::SwarmState>) {
    return decode_swarm_state(bytes.data(), bytes.size(), sample, layout);
  } else if constexpr (std::is_same_v<T, msg::DistanceScan>) {
    return decode_distance_scan(bytes.data(), bytes.size(), sample, layout);
  } else {
    typename Topic<T>::PubSub type;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
    std::memcpy(payload.data, bytes.data(), bytes.size());
    payload.length = static_cast<std::uint32_t>(bytes.size());
    try {
      return type.deserialize(&payload, &sample);
    } catch (const std::exception&) {  // fastcdr throws on truncated data
      return false;
    }
  }
}

}  // namespace ddswarm
