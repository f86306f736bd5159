#include "agent/law_registry.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "agent/law_plugin.hpp"
#include "agent/laws/olfati_saber.hpp"
#include "agent/laws/reynolds.hpp"
#include "agent/laws/vasarhelyi.hpp"
#include "agent/swarm_law.hpp"

namespace ddswarm::agent {
namespace {

/// The thesis's law through the law interface: C + V_mission (Eq. 3.2, 3.4),
/// with C_s left to the framework. Evaluated exactly as evaluate_law does,
/// so a thesis swarm flies bit for bit as before the interface existed.
class ThesisLaw final : public law::SwarmLaw {
 public:
  explicit ThesisLaw(const ActivationConfig& a) : activation_(a) {}

  law::Command step(const law::Observation& o) override {
    positions_.clear();
    for (const auto& p : o.peers) positions_.push_back(p.p_world);
    Eigen::Vector3d swarm =
        repulsion_attraction(o.p_world, positions_, o.inter_distance_m, activation_);
    if (o.phase == law::Phase::kLanding) swarm.z() = 0;
    return {swarm + o.mission_velocity, 0.0};
  }

 private:
  ActivationConfig activation_;
  std::vector<Eigen::Vector3d> positions_;
};

/// agent.law.fault: the wrapped law, until fault_after_s; then a throw or a NaN.
class FaultyLaw final : public law::SwarmLaw {
 public:
  FaultyLaw(std::unique_ptr<law::SwarmLaw> inner, LawConfig::Fault f, double after_s)
      : inner_(std::move(inner)), fault_(f), after_s_(after_s) {}

  law::Command step(const law::Observation& o) override {
    if (o.sim_time_s < after_s_) return inner_->step(o);
    if (fault_ == LawConfig::Fault::kThrow)
      throw std::runtime_error("injected fault (agent.law.fault: throw)");
    return {Eigen::Vector3d::Constant(std::nan("")), 0.0};
  }
  bool uses_obstacle_term() const override { return inner_->uses_obstacle_term(); }

 private:
  std::unique_ptr<law::SwarmLaw> inner_;
  LawConfig::Fault fault_;
  double after_s_;
};

/// agent.law.obstacles: law or framework, whatever the law would choose.
class ObstaclesBy final : public law::SwarmLaw {
 public:
  ObstaclesBy(std::unique_ptr<law::SwarmLaw> inner, bool framework)
      : inner_(std::move(inner)), framework_(framework) {}

  law::Command step(const law::Observation& o) override {
    if (!framework_) return inner_->step(o);
    law::Observation blind = o;
    blind.rays = {};
    return inner_->step(blind);
  }
  bool uses_obstacle_term() const override { return framework_; }

 private:
  std::unique_ptr<law::SwarmLaw> inner_;
  bool framework_;
};

}  // namespace

std::unique_ptr<law::SwarmLaw> make_law(const LawConfig& c, const law::LawContext& ctx,
                                        law::Rng rng, const AgentConfig& agent) {
  auto values = c.params;
  if (c.type == LawType::kPython) {
    values["ddswarm:module"] = c.module;
    values["ddswarm:class"] = c.class_name;
  }
  law::Params p(c.path + ".params", std::move(values));
  std::unique_ptr<law::SwarmLaw> l;
  switch (c.type) {
    case LawType::kThesis:
      l = std::make_unique<ThesisLaw>(agent.activation);
      break;
    case LawType::kReynolds:
      l = laws::make_reynolds(p, rng, ctx);
      break;
    case LawType::kOlfatiSaber:
      l = laws::make_olfati_saber(p, rng, ctx);
      break;
    case LawType::kVasarhelyi:
      l = laws::make_vasarhelyi(p, rng, ctx);
      break;
    case LawType::kPython: {
      const std::string lib = python_law_plugin();
      std::error_code ec;
      if (!std::filesystem::is_regular_file(lib, ec))
        throw law::ParamError(c.path + ".type", "python",
                              "this ddswarm was built without Python laws (" + lib +
                                  " is missing): scripts/setup installs python3-dev and "
                                  "python3-pybind11, then rebuild");
      l = plugin_factory(lib, c.path + ".type")(p, rng, ctx);
      break;
    }
    case LawType::kPlugin:
      l = plugin_factory(c.library, c.path + ".library")(p, rng, ctx);
      if (!l) throw law::ParamError(c.path + ".library", c.library, "its factory made no law");
      break;
  }
  p.finish();
  if (c.obstacles != LawConfig::Obstacles::kAuto)
    l = std::make_unique<ObstaclesBy>(std::move(l),
                                      c.obstacles == LawConfig::Obstacles::kFramework);
  if (c.fault != LawConfig::Fault::kNone)
    l = std::make_unique<FaultyLaw>(std::move(l), c.fault, c.fault_after_s);
  return l;
}

std::string python_law_plugin() {
  if (const char* env = std::getenv("DDSWARM_PYTHON_LAW"); env && *env) return env;
  // Beside the executables: bin/../lib/ddswarm, in the build tree as installed.
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return (exe.parent_path().parent_path() / "lib/ddswarm/libddswarm_python_law.so").string();
}

std::uint64_t law_seed(std::uint64_t scenario_seed, int drone_id) {
  return scenario_seed * 0x9e3779b97f4a7c15ULL ^ (0x1a3ULL << 32) ^
         static_cast<std::uint64_t>(drone_id);
}

}  // namespace ddswarm::agent
