#pragma once
// A wait for a count to reach its goal that tells "still coming up" from
// "nothing more coming": past its timeout it goes on while the count keeps
// reaching new highs. A pure rule, free of DDS and clocks (wait-agents).

#include <algorithm>

namespace ddswarm::gs {

class GrowingWait {
 public:
  /// Past start_s + timeout_s the wait goes on for grace_s after each rise
  /// of the count over the last high: the first count seen is where it starts
  /// from, and a count that never rose never extends the wait.
  GrowingWait(double start_s, double timeout_s, double grace_s)
      : timeout_at_(start_s + timeout_s), grace_s_(grace_s) {}

  /// The count seen at now_s (< 0: nothing seen, such as no server).
  void saw(int count, double now_s) {
    if (count < 0) return;
    if (high_ >= 0 && count > high_) {
      rose_ = true;
      rose_at_ = now_s;
    }
    high_ = std::max(high_, count);
  }
  /// When the wait gives up, as of what it has seen.
  double until_s() const {
    return rose_ ? std::max(timeout_at_, rose_at_ + grace_s_) : timeout_at_;
  }
  /// Whether growth moved the end past the timeout.
  bool extended() const { return until_s() > timeout_at_; }
  /// Whether now_s lies past the timeout (the wait goes on for growth alone).
  bool past_timeout(double now_s) const { return now_s > timeout_at_; }

 private:
  double timeout_at_, grace_s_;
  int high_ = -1;  ///< the highest count seen; -1: none yet
  bool rose_ = false;
  double rose_at_ = 0;
};

}  // namespace ddswarm::gs
