#include "agent/agent_config.hpp"

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "agent/law_registry.hpp"
#include "common/id_ranges.hpp"

namespace ddswarm::agent {
namespace {

std::string point_text(const Eigen::Vector2d& p) {
  return "[" + to_text(p.x()) + ", " + to_text(p.y()) + "]";
}

std::string point_field(const std::string& prefix, std::size_t i) {
  return prefix + ".points[" + std::to_string(i) + "]";
}

void check_increasing(const std::string& prefix, const std::vector<Eigen::Vector2d>& pts) {
  if (pts.size() < 2)
    throw FieldError(prefix + ".points", std::to_string(pts.size()) + " points",
                     "a custom curve needs at least 2 points");
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (!(pts[i].x() > pts[i - 1].x()))
      throw FieldError(point_field(prefix, i), point_text(pts[i]),
                       "points must be sorted by strictly increasing distance");
}

}  // namespace

void ActivationConfig::validate() const {
  const std::string p = "agent.activation";
  FieldChecker check(p);
  fields(*this, check);
  if (repulsion_gain < attraction_gain)
    throw FieldError(p + ".repulsion_gain", to_text(repulsion_gain),
                     "must be >= attraction_gain (" + to_text(attraction_gain) +
                         "): repulsion must be the stronger force for the drones' safety");
  if (neighbours < 0 || neighbours > kMaxNeighbours)
    throw FieldError(p + ".neighbours", std::to_string(neighbours),
                     "must be 0 (every peer) or 1.." + std::to_string(kMaxNeighbours));
  if (type == ActivationType::kLinear) {
    if (!points.empty())
      throw FieldError(p + ".points", std::to_string(points.size()) + " points",
                       "only used with type: custom");
    return;
  }
  check_increasing(p, points);
  bool origin = false, below = false, above = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = points[i].x(), f = points[i].y();
    if (d == 0.0) {
      if (f != 0.0)
        throw FieldError(point_field(p, i), point_text(points[i]),
                         "the curve must pass through (0, 0): no force at D_int");
      origin = true;
    } else if (d < 0.0) {
      if (!(f < 0.0))
        throw FieldError(point_field(p, i), point_text(points[i]),
                         "f must be < 0 (repulsive) where D_r < 0");
      below = true;
    } else {
      if (!(f > 0.0))
        throw FieldError(point_field(p, i), point_text(points[i]),
                         "f must be > 0 (attractive) where D_r > 0");
      above = true;
    }
  }
  if (!origin)
    throw FieldError(p + ".points", std::to_string(points.size()) + " points",
                     "the curve must contain the point [0, 0]");
  if (!below || !above)
    throw FieldError(p + ".points", std::to_string(points.size()) + " points",
                     "the curve needs points on both sides of 0 (repulsion and attraction)");
}

void SensorFunctionConfig::validate() const {
  const std::string p = "agent.sensor_function";
  FieldChecker check(p);
  fields(*this, check);
  if (type != SensorFunctionType::kCustom) {
    if (!points.empty())
      throw FieldError(p + ".points", std::to_string(points.size()) + " points",
                       "only used with type: custom");
    return;
  }
  check_increasing(p, points);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].x() < 0.0)
      throw FieldError(point_field(p, i), point_text(points[i]), "distance S must be >= 0");
    if (!(points[i].y() >= 0.0))
      throw FieldError(point_field(p, i), point_text(points[i]),
                       "f must be >= 0 (a push away from the obstacle)");
  }
  if (points.back().y() != 0.0)
    throw FieldError(point_field(p, points.size() - 1), point_text(points.back()),
                     "the last point must have f = 0 (its S is the function's range)");
}

const char* to_string(LawType t) {
  switch (t) {
    case LawType::kThesis:
      return "thesis";
    case LawType::kReynolds:
      return "reynolds";
    case LawType::kOlfatiSaber:
      return "olfati_saber";
    case LawType::kVasarhelyi:
      return "vasarhelyi";
    case LawType::kPlugin:
      return "plugin";
    case LawType::kPython:
      return "python";
  }
  return "?";
}

void LawConfig::validate() const {
  if (type != LawType::kPlugin && !library.empty())
    throw FieldError(path + ".library", library, "only used with type: plugin");
  if (type != LawType::kPython && !module.empty())
    throw FieldError(path + ".module", module, "only used with type: python");
  if (type != LawType::kPython && !class_name.empty())
    throw FieldError(path + ".class", class_name, "only used with type: python");
  FieldChecker check(path);
  fields(*this, check);
  if (fault == Fault::kNone && fault_after_s > 0)
    throw FieldError(path + ".fault_after_s", to_text(fault_after_s), "needs fault: nan or throw");
  law::LawContext ctx;
  ctx.drone_id = 0;
  ctx.num_drones = 1;
  try {
    make_law(*this, ctx, law::Rng(0), AgentConfig{});
  } catch (const law::ParamError& e) {
    throw FieldError(e.field(), e.value(), e.reason());
  } catch (const std::exception& e) {
    throw FieldError(path + (type == LawType::kPlugin   ? ".library"
                             : type == LawType::kPython ? ".class"
                                                        : ".type"),
                     type == LawType::kPlugin   ? library
                     : type == LawType::kPython ? class_name
                                                : to_string(type),
                     std::string("the law could not be built: ") + e.what());
  }
}

std::string LawConfig::name() const {
  if (type == LawType::kPython) return "python " + class_name;
  if (type != LawType::kPlugin) return to_string(type);
  const auto slash = library.find_last_of('/');
  return "plugin " + (slash == std::string::npos ? library : library.substr(slash + 1));
}

const LawConfig& AgentConfig::law_for(int id) const {
  for (auto it = overrides.rbegin(); it != overrides.rend(); ++it)
    for (int i : it->ids)
      if (i == id) return it->law;
  return law;
}

void AgentConfig::validate() const {
  law.validate();
  std::set<int> taken;
  for (std::size_t k = 0; k < overrides.size(); ++k) {
    const auto& o = overrides[k];
    const std::string at = "agent.overrides[" + std::to_string(k) + "]";
    if (o.ids.empty()) throw FieldError(at + ".ids", o.ids_text, "names no drone");
    for (int id : o.ids)
      if (!taken.insert(id).second)
        throw FieldError(at + ".ids", o.ids_text,
                         "drone " + std::to_string(id) + " is in an earlier override too");
    o.law.validate();
  }
  FieldChecker check("agent");
  fields(*this, check);
  activation.validate();
  if (activation.cutoff_m > 0 && !(activation.cutoff_m > inter_distance_m))
    throw FieldError("agent.activation.cutoff_m", to_text(activation.cutoff_m),
                     "must be 0 (no cutoff) or > inter_distance_m (" + to_text(inter_distance_m) +
                         "), or drones would never attract");
  sensor_function.validate();
  if (takeoff_altitude_m < min_altitude_m)
    throw FieldError("agent.takeoff_altitude_m", to_text(takeoff_altitude_m),
                     "must be >= min_altitude_m (" + to_text(min_altitude_m) + ")");
  for (auto [name, v] : {std::pair{"agent.takeoff_speed_mps", takeoff_speed_mps},
                         std::pair{"agent.landing_speed_mps", landing_speed_mps},
                         std::pair{"agent.task_speed_mps", task_speed_mps}}) {
    if (v > max_speed_mps)
      throw FieldError(name, to_text(v),
                       "must be <= max_speed_mps (" + to_text(max_speed_mps) + ")");
  }
}

void load(YamlSection s, ActivationConfig& c) {
  FieldLoader load(s);
  ActivationConfig::fields(c, load);
  s.finish();
}

void load(YamlSection s, SensorFunctionConfig& c) {
  FieldLoader load(s);
  SensorFunctionConfig::fields(c, load);
  s.finish();
}

void load(YamlSection s, LawConfig& c) {
  c.path = s.path();
  FieldLoader load(s);
  LawConfig::fields(c, load);
  YamlSection p = s.child("params");
  if (p.node().IsMap()) {
    for (auto it = p.node().begin(); it != p.node().end(); ++it) {
      const std::string key = it->first.Scalar();
      if (!it->second.IsScalar())
        p.fail(it->second, key, "(not a scalar)",
               "a law parameter must be a number, true/false or a word");
      std::string value;
      p.get(key, value);
      c.params[key] = value;
    }
  }
  p.finish();
  s.finish();
}

void load(YamlSection s, AgentConfig& c) {
  load(s.child("law"), c.law);
  auto overrides = s.children("overrides");
  for (std::size_t k = 0; k < overrides.size(); ++k) {
    auto& o = overrides[k];
    LawOverride lo;
    o.get("ids", lo.ids_text);
    try {
      // The scenario's drone count is checked by the agent, which knows it.
      lo.ids = parse_id_ranges(lo.ids_text, 1 << 16);
    } catch (const std::invalid_argument& e) {
      std::string why = e.what();
      if (auto colon = why.find(": "); colon != std::string::npos) why = why.substr(colon + 2);
      throw FieldError(o.path() + ".ids", lo.ids_text, why);
    }
    load(o.child("law"), lo.law);
    o.finish();
    c.overrides.push_back(std::move(lo));
  }
  load(s.child("activation"), c.activation);
  load(s.child("sensor_function"), c.sensor_function);
  FieldLoader fields(s);
  AgentConfig::fields(c, fields);
  s.finish();
}

}  // namespace ddswarm::agent
