#include "sim_server/tick_barrier.hpp"

namespace ddswarm::sim {

TickBarrier::TickBarrier(int drones, Pipeline pipeline)
    : pipeline_(pipeline), seats_(static_cast<std::size_t>(drones)) {}

void TickBarrier::join(int i) {
  Seat& s = seats_[i];
  s.answered = false;
  ++unanswered_;
  s.answered_prev = true;
}

void TickBarrier::lose(int i) {
  Seat& s = seats_[i];
  if (!s.answered) --unanswered_;
  if (!s.answered_prev) --unanswered_prev_;
  s.answered_prev = true;
}

bool TickBarrier::answer(int i, std::uint64_t tick, const CommandView& now) {
  Seat& s = seats_[i];
  bool wake = false;
  // Pipelined real time: a late answer still flies the coming step, but an
  // answer to the state just published waits for the step after it.
  if (pipeline_ == Pipeline::kRealtime && tick < published_) s.latched = now;
  if (pipeline_ == Pipeline::kRealtime && tick + 1 == published_ && !s.answered_prev) {
    s.answered_prev = true;
    wake |= --unanswered_prev_ == 0;
  }
  if (tick == published_ && !s.answered) {
    s.answered = true;
    wake |= --unanswered_ == 0;
  }
  return wake;
}

}  // namespace ddswarm::sim
