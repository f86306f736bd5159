#pragma once
// The swarm state's wire decoder: every agent, the ground station and the
// recorder read a whole-swarm sample every tick, and at 128 drones the
// generated code spent a fifth of an agent's CPU in Fast CDR's out-of-line
// calls, one per field (docs/performance.md). This decoder reads the same
// CDR (XCDR1, either byte order) with inline loads and gives the same
// sample, field for field, or refuses the buffer.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "SwarmState.h"

namespace ddswarm {

/// How a DistanceScan lies in the bytes: as this build writes it, or as
/// recordings made before scans carried elevations do (a horizontal ring of
/// at most 64 rays: yaw, range, hit). A kRing64 scan decodes with every
/// elevation 0, which is what its rays were.
enum class ScanLayout { kCurrent, kRing64 };

/// Decodes a serialized SwarmState: `data` starts at the 4-byte
/// encapsulation header, as a Fast DDS payload does. Returns false, leaving
/// `out` unspecified, for a buffer that ends early or holds a sequence
/// longer than its IDL bound. What it accepts, the generated code accepts
/// too, and yields the same sample (common/swarm_state_cdr_test.cpp); bytes
/// after the sample are ignored, as there. With kRing64 it reads an older
/// recording's samples.
bool decode_swarm_state(const std::uint8_t* data, std::size_t size, msg::SwarmState& out,
                        ScanLayout layout = ScanLayout::kCurrent);

/// Decodes a serialized DistanceScan (the ddswarm/scan topic) as
/// decode_swarm_state does a SwarmState.
bool decode_distance_scan(const std::uint8_t* data, std::size_t size, msg::DistanceScan& out,
                          ScanLayout layout = ScanLayout::kCurrent);

/// The layout a recording's schema describes: its IDL text (MCAP omgidl
/// schema, as ddswarm-record writes kIdlText) with a DistanceScan struct that
/// declares no elevation_body_rad is kRing64; anything else, or no text, kCurrent.
ScanLayout scan_layout_of(std::string_view schema_idl);

/// The bytes the generated code puts on the wire for `s`, encapsulation
/// first, in the byte order asked (Fast DDS writes the machine's): what the
/// decoder is checked against in its test, fuzz target and bench. With
/// kRing64, the bytes a recording made before scans carried elevations
/// holds (each scan's elevations left out), for the readers' tests.
std::vector<std::uint8_t> encode_swarm_state(const msg::SwarmState& s, bool big_endian = false,
                                             ScanLayout layout = ScanLayout::kCurrent);

}  // namespace ddswarm
