#include "ground_station/sequence_gaps.hpp"

#include <algorithm>

namespace ddswarm::gs {

void SequenceGaps::received(const WriterId& writer, std::uint64_t sequence) {
  auto [it, first] = span_.try_emplace(writer, Span{sequence, sequence, 1});
  if (first) return;
  Span& s = it->second;
  s.lowest = std::min(s.lowest, sequence);
  s.highest = std::max(s.highest, sequence);
  ++s.count;
}

std::uint64_t SequenceGaps::missed() const {
  std::uint64_t n = 0;
  for (const auto& [writer, s] : span_) {
    const std::uint64_t owed = s.highest - s.lowest + 1;
    n += owed > s.count ? owed - s.count : 0;
  }
  return n;
}

}  // namespace ddswarm::gs
