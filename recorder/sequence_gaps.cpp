#include "recorder/sequence_gaps.hpp"

namespace ddswarm::gs {

void SequenceGaps::add_hole(Span& s, std::uint64_t first, std::uint64_t last) {
  if (first > last) return;
  s.holes.emplace(first, last);
  s.missing += last - first + 1;
}

bool SequenceGaps::received(const WriterId& writer, std::uint64_t sequence) {
  auto [it, first] = span_.try_emplace(writer, Span{sequence, sequence, {}, 0});
  if (first) return true;
  Span& s = it->second;
  if (sequence > s.highest) {
    add_hole(s, s.highest + 1, sequence - 1);
    s.highest = sequence;
    return true;
  }
  if (sequence < s.lowest) {  // older than the first received: the span grows down
    add_hole(s, sequence + 1, s.lowest - 1);
    s.lowest = sequence;
    return true;
  }
  // Within the span: new only if it fills a hole (a repair that came after a
  // newer sample of another instance).
  auto h = s.holes.upper_bound(sequence);
  if (h == s.holes.begin()) return false;
  --h;
  const auto [lo, hi] = *h;
  if (sequence > hi) return false;
  s.holes.erase(h);
  s.missing -= hi - lo + 1;
  if (sequence > lo) add_hole(s, lo, sequence - 1);
  if (sequence < hi) add_hole(s, sequence + 1, hi);
  return true;
}

std::uint64_t SequenceGaps::missed() const {
  std::uint64_t n = 0;
  for (const auto& [writer, s] : span_) n += s.missing;
  return n;
}

}  // namespace ddswarm::gs
