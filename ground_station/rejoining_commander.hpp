#pragma once
// The console's commander across a stop. A console left at its prompt may be
// stopped (Ctrl-Z, then fg) or starved for longer than the DDS lease it
// announces: its peers then drop it while it still holds them, and Fast DDS
// 2.9 does not always match the two sides again (docs/faults.md). Agents and
// the recorder watch their own loops for that gap and join again; the
// console waits for a line instead, so a thread of its own watches here.
// Before the next command, the old participant leaves and a new one joins.
#include <atomic>
#include <functional>
#include <iosfwd>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "common/process.hpp"
#include "ground_station/commander.hpp"

namespace ddswarm::gs {

class RejoiningCommander final : public Commander {
 public:
  /// Makes a commander on a new participant and waits for the server (the
  /// old one has left by then). May throw: the menu reports it, and the
  /// next command tries again.
  using Join = std::function<std::unique_ptr<Commander>()>;

  /// first: the commander already joined. lease_s: dds.lease_duration_s.
  /// The watch turns every watch_period_s on clock (wall seconds).
  RejoiningCommander(std::unique_ptr<Commander> first, Join join, double lease_s, std::ostream& log,
                     std::function<double()> clock = wall_seconds, double watch_period_s = 0.1);
  ~RejoiningCommander() override;
  RejoiningCommander(const RejoiningCommander&) = delete;
  RejoiningCommander& operator=(const RejoiningCommander&) = delete;

  /// How many times a new participant has joined.
  int rejoins() const { return rejoins_; }

  CommandResult takeoff(double altitude_m) override { return current().takeoff(altitude_m); }
  CommandResult move(const Eigen::Vector3d& v_enu, double duration_s) override {
    return current().move(v_enu, duration_s);
  }
  CommandResult set_distance(double d_int_m) override { return current().set_distance(d_int_m); }
  CommandResult land() override { return current().land(); }
  CommandResult follow_leader(int leader_id) override { return current().follow_leader(leader_id); }
  CommandResult teleop(const Eigen::Vector3d& v_enu) override { return current().teleop(v_enu); }
  CommandResult hold() override { return current().hold(); }
  CommandResult task(double speed_mps, double epsilon_m) override {
    return current().task(speed_mps, epsilon_m);
  }
  std::string wait_task(std::function<void(const std::string&)> on_progress) override {
    return current().wait_task(std::move(on_progress));
  }
  SwarmStatus status() override { return current().status(); }

 private:
  /// The commander to use: a new one first when the watch saw a stop
  /// longer than the lease (or the last join failed).
  Commander& current();

  std::unique_ptr<Commander> commander_;
  Join join_;
  std::ostream& log_;
  std::function<double()> clock_;
  std::mutex mu_;
  std::string why_;  // under mu_: the watch's reason to join again, "" = none
  std::atomic<bool> stop_{false};
  int rejoins_ = 0;
  std::thread watch_;
};

}  // namespace ddswarm::gs
