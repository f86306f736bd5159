#pragma once
// The swarm state's wire decoder: every agent, the ground station and the
// recorder read a whole-swarm sample every tick, and at 128 drones the
// generated code spent a fifth of an agent's CPU in Fast CDR's out-of-line
// calls, one per field (docs/performance.md). This decoder reads the same
// CDR (XCDR1, either byte order) with inline loads and gives the same
// sample, field for field, or refuses the buffer.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "SwarmState.h"

namespace ddswarm {

/// Decodes a serialized SwarmState: `data` starts at the 4-byte
/// encapsulation header, as a Fast DDS payload does. Returns false, leaving
/// `out` unspecified, for a buffer that ends early or holds a sequence
/// longer than its IDL bound. What it accepts, the generated code accepts
/// too, and yields the same sample (common/swarm_state_cdr_test.cpp); bytes
/// after the sample are ignored, as there.
bool decode_swarm_state(const std::uint8_t* data, std::size_t size, msg::SwarmState& out);

/// The bytes the generated code puts on the wire for `s`, encapsulation
/// first, in the byte order asked (Fast DDS writes the machine's): what the
/// decoder is checked against in its test, fuzz target and bench.
std::vector<std::uint8_t> encode_swarm_state(const msg::SwarmState& s, bool big_endian = false);

}  // namespace ddswarm
