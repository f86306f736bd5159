#include "ground_station/rejoining_commander.hpp"

#include <chrono>
#include <ostream>
#include <stdexcept>

namespace ddswarm::gs {

RejoiningCommander::RejoiningCommander(std::unique_ptr<Commander> first, Join join, double lease_s,
                                       std::ostream& log, std::function<double()> clock,
                                       double watch_period_s)
    : commander_(std::move(first)), join_(std::move(join)), log_(log), clock_(std::move(clock)) {
  watch_ = std::thread([this, lease_s, watch_period_s] {
    LeaseWatch lease(lease_s, clock_());
    const auto period = std::chrono::duration<double>(watch_period_s);
    while (!stop_.load()) {
      std::this_thread::sleep_for(period);
      std::string why = lease.turn(clock_());
      if (why.empty()) continue;
      std::lock_guard<std::mutex> lock(mu_);
      why_ = std::move(why);  // the last stop's length is the one to report
    }
  });
}

RejoiningCommander::~RejoiningCommander() {
  stop_ = true;
  watch_.join();
}

Commander& RejoiningCommander::current() {
  std::string why;
  {
    std::lock_guard<std::mutex> lock(mu_);
    why.swap(why_);
  }
  if (!why.empty()) {
    log_ << "ddswarm-gs: " << why << "\n" << std::flush;
    settle_after_stop();
    commander_.reset();  // the old participant leaves before the new one joins
  }
  if (!commander_) {
    commander_ = join_();  // throws on failure: the next command tries again
    if (!commander_) throw std::runtime_error("joining DDS again gave no ground station");
    ++rejoins_;
  }
  return *commander_;
}

}  // namespace ddswarm::gs
