#pragma once
// Samples a reader never received, from the gaps in each writer's sequence
// numbers. DDS numbers every sample a writer sends, across all its
// instances, and delivers each at most once; a reader that got 7, 8 and 10
// from one writer missed 9, whatever its QoS (a best-effort loss, a KEEP_LAST
// writer that replaced it before a slow reliable reader got it). Samples may
// arrive out of order (a keyed reliable reader can deliver one instance's
// repair after another's newer sample), so a gap counts only if it is never
// filled. Fast DDS 2.9.1's sample-lost status reports such losses only
// sometimes, so the recorder counts them here.
#include <array>
#include <cstdint>
#include <map>

namespace ddswarm::gs {

class SequenceGaps {
 public:
  using WriterId = std::array<std::uint8_t, 16>;  ///< the writer's GUID
  /// Records a received sample. False when that writer's number was already
  /// received: a duplicate, e.g. the transient-local history a reader that
  /// joined again gets once more. Keep only samples this returns true for.
  bool received(const WriterId& writer, std::uint64_t sequence);
  /// Samples missing between each writer's lowest and highest number
  /// received: a reader that joined late was owed nothing before its first.
  std::uint64_t missed() const;
  std::size_t writers() const { return span_.size(); }

 private:
  struct Span {
    std::uint64_t lowest, highest;
    std::map<std::uint64_t, std::uint64_t> holes;  ///< first -> last number never received
    std::uint64_t missing = 0;                     ///< numbers in holes
  };
  static void add_hole(Span& s, std::uint64_t first, std::uint64_t last);
  std::map<WriterId, Span> span_;
};

}  // namespace ddswarm::gs
