// A law that breaks its process on purpose (a segmentation fault) from
// crash_after_s of sim time on, for testing that a crashing plug-in takes
// down its own drone only: the server's failsafe lands it, the others fly on.
#include <csignal>
#include <ddswarm/law.hpp>

namespace {

using namespace ddswarm::law;

class CrashLaw final : public SwarmLaw {
 public:
  explicit CrashLaw(double after_s) : after_s_(after_s) {}
  Command step(const Observation& o) override {
    if (o.sim_time_s >= after_s_) std::raise(SIGSEGV);
    return {o.mission_velocity, 0.0};
  }

 private:
  double after_s_;
};

std::unique_ptr<SwarmLaw> make(Params& p, Rng, const LawContext&) {
  return std::make_unique<CrashLaw>(p.number("crash_after_s", 10.0, 0.0, 1e6));
}

}  // namespace

DDSWARM_LAW_PLUGIN(make)
