#pragma once
// Which answers a published tick still needs. Pure: no DDS, no clock, no
// locks; the server calls it with its own mutex held.
//
// Every tick the server publishes asks each live agent for one answer (a
// velocity command for that tick). Lockstep waits for all of them before it
// steps; real time waits for them up to a grace past the period's end. The
// two pipelines (sim.lockstep_pipeline, sim.realtime_pipeline) fly each
// answer one tick later: the barrier latches the commands in force as a tick
// goes out, and those fly the step after it.
#include <cstdint>
#include <vector>

#include "sim_server/flight_controller.hpp"

namespace ddswarm::sim {

/// The part of a drone's agent record that decides its setpoint for one period.
struct CommandView {
  VelocitySetpoint setpoint;       ///< last accepted command (world frame, m/s, rad/s)
  bool has_command = false;        ///< any command accepted yet
  std::uint64_t command_tick = 0;  ///< the tick that command answered
  bool live = false;               ///< its agent is live
};

/// How answers fly.
enum class Pipeline {
  kNone,      ///< an answer to tick k flies the step k -> k+1
  kLockstep,  ///< the world steps k -> k+1 while agents answer k; their answers fly k+1 -> k+2
  kRealtime,  ///< as kLockstep, in real time; a late answer to k-1 still flies k -> k+1
};

class TickBarrier {
 public:
  TickBarrier(int drones, Pipeline pipeline);

  /// Tick `tick` goes out. now(i) is drone i's CommandView at this moment:
  /// who is live, and (pipelined) the command latched for the coming step.
  /// Every live drone owes an answer to `tick`; an answer to the tick before
  /// that has not come is owed too (kRealtime waits for it).
  template <class Now>
  void publish(std::uint64_t tick, Now&& now) {
    published_ = tick;
    unanswered_ = 0;
    unanswered_prev_ = 0;
    for (int i = 0; i < static_cast<int>(seats_.size()); ++i) {
      Seat& s = seats_[i];
      const CommandView v = now(i);
      if (pipeline_ != Pipeline::kNone) s.latched = v;
      s.answered_prev = s.answered;
      unanswered_prev_ += v.live && !s.answered;
      s.answered = false;
      unanswered_ += v.live;
    }
  }

  /// Drone i's agent (not live) became live: it owes an answer to the published tick,
  /// none to a tick published before it was heard.
  void join(int i);
  /// Drone i's live agent was lost: it owes nothing.
  void lose(int i);
  /// Drone i's agent answered `tick` (an accepted command); now is its
  /// CommandView with that answer in. True when it was the last answer owed
  /// to the published tick, or (kRealtime) to the one before it: the caller
  /// wakes the loop (one wake-up per tick, not one per answer).
  bool answer(int i, std::uint64_t tick, const CommandView& now);

  /// The newest tick published.
  std::uint64_t published() const { return published_; }
  /// Answers the loop waits for: to the published tick, or (kRealtime) to the one before it.
  int waiting() const { return pipeline_ == Pipeline::kRealtime ? unanswered_prev_ : unanswered_; }
  /// Live drones that have not answered the published tick.
  int unanswered() const { return unanswered_; }
  /// Of the drones live at the publish, those that have not answered the tick before it.
  int unanswered_prev() const { return unanswered_prev_; }
  /// Pipelined: the command that flies drone i's coming step.
  const CommandView& latched(int i) const { return seats_[i].latched; }
  Pipeline pipeline() const { return pipeline_; }

 private:
  struct Seat {
    bool answered = false;       ///< answered the published tick
    bool answered_prev = false;  ///< answered the tick before it
    CommandView latched;
  };
  Pipeline pipeline_;
  std::vector<Seat> seats_;
  std::uint64_t published_ = 0;
  int unanswered_ = 0;
  int unanswered_prev_ = 0;
};

}  // namespace ddswarm::sim
