// A swarm law of one's own: every peer within a radius pulls or pushes this
// drone like a spring whose rest length is D_int, added to the mission's
// velocity. The framework adds the obstacle term, holds the altitude and
// limits the speed (docs/laws.md).
#include <ddswarm/law.hpp>

namespace {

using namespace ddswarm::law;

class SpringLaw final : public SwarmLaw {
 public:
  SpringLaw(double gain, double radius_m) : gain_(gain), radius_m_(radius_m) {}

  Command step(const Observation& o) override {
    Eigen::Vector3d v = o.mission_velocity;
    for (const Peer& p : o.peers) {
      const Eigen::Vector3d d = p.p_world - o.p_world;
      const double dist = d.norm();
      if (dist < 1e-6 || dist > radius_m_) continue;
      v += gain_ * (dist - o.inter_distance_m) * d / dist;
    }
    return {v, 0.0};
  }

 private:
  double gain_, radius_m_;
};

std::unique_ptr<SwarmLaw> make(Params& p, Rng, const LawContext& ctx) {
  const double gain = p.number("gain", 0.4, 0.0, 10.0);                                 // 1/s
  const double radius = p.number("radius_m", 3.0 * ctx.inter_distance_m, 0.1, 1000.0);  // m
  return std::make_unique<SpringLaw>(gain, radius);
}

}  // namespace

DDSWARM_LAW_PLUGIN(make)
