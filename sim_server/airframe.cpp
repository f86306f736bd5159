#include "sim_server/airframe.hpp"

#include <map>
#include <stdexcept>

#include "common/id_ranges.hpp"

namespace ddswarm::sim {
namespace {

/// The FieldError e again, its field "from.x" named "to.x".
[[noreturn]] void rethrow_under(const FieldError& e, const std::string& from,
                                const std::string& to) {
  const std::string& f = e.field();
  const std::string rest = std::string(e.what()).substr(f.size() + 3);  // after " = "
  const auto colon = rest.find(": ");
  const std::string field = f.rfind(from, 0) == 0 ? to + f.substr(from.size()) : to + "." + f;
  throw FieldError(field, rest.substr(0, colon),
                   colon == std::string::npos ? "" : rest.substr(colon + 2));
}

/// "0-2,5" from sorted ids.
std::string ranges_of(const std::vector<int>& ids) {
  std::string out;
  for (std::size_t k = 0; k < ids.size();) {
    std::size_t e = k;
    while (e + 1 < ids.size() && ids[e + 1] == ids[e] + 1) ++e;
    out += (out.empty() ? "" : ",") + std::to_string(ids[k]);
    if (e > k) out += "-" + std::to_string(ids[e]);
    k = e + 1;
  }
  return out;
}

}  // namespace

void load_airframes(YamlSection s, QuadrotorParams& q, ControllerConfig& c,
                    std::vector<AirframeGroup>& groups) {
  const std::map<std::string, Airframe> names(airframe_names().begin(), airframe_names().end());
  Airframe a = q.airframe;
  s.get_enum("airframe", a, names);
  if (a != q.airframe) q = QuadrotorParams::preset(a);
  c = ControllerConfig::preset(a);
  FieldLoader fields(s);
  QuadrotorParams::fields(q, fields);
  groups.clear();
  for (YamlSection g : s.children("groups")) {
    AirframeGroup group;
    g.get("ids", group.ids);
    if (group.ids.empty()) g.fail(g.node(), "ids", "\"\"", "every group needs its drone ids");
    Airframe ga = Airframe::kGeneric;
    g.get_enum("airframe", ga, names);
    group.quadrotor = QuadrotorParams::preset(ga);
    group.controller = ControllerConfig::preset(ga);
    YamlSection gq = g.child("quadrotor");
    FieldLoader qf(gq);
    QuadrotorParams::fields(group.quadrotor, qf);
    group.quadrotor.airframe = ga;  // the group's airframe is its own key
    gq.finish();
    load(g.child("controller"), group.controller);
    g.finish();
    groups.push_back(std::move(group));
  }
  s.finish();
}

Fleet make_fleet(const QuadrotorParams& q, const ControllerConfig& c,
                 const std::vector<AirframeGroup>& groups, int drones) {
  Fleet f;
  f.quadrotors.push_back(q);
  f.controllers.push_back(c);
  f.airframe_of.assign(static_cast<std::size_t>(drones), 0);
  std::vector<int> group_of(static_cast<std::size_t>(drones), -1);
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const AirframeGroup& g = groups[k];
    const std::string at = "quadrotor.groups[" + std::to_string(k) + "]";
    try {
      g.quadrotor.validate();
    } catch (const FieldError& e) {
      rethrow_under(e, "quadrotor", at + ".quadrotor");
    }
    try {
      g.controller.validate();
    } catch (const FieldError& e) {
      rethrow_under(e, "controller", at + ".controller");
    }
    std::vector<int> ids;
    try {
      ids = parse_id_ranges(g.ids, drones);
    } catch (const std::invalid_argument& e) {
      std::string why = e.what();
      const auto colon = why.find(": ");
      if (colon != std::string::npos) why = why.substr(colon + 2);
      throw FieldError(at + ".ids", "\"" + g.ids + "\"", why);
    }
    for (int id : ids) {
      if (group_of[id] >= 0)
        throw FieldError(at + ".ids", "\"" + g.ids + "\"",
                         "drone " + std::to_string(id) + " is already in groups[" +
                             std::to_string(group_of[id]) + "]");
      group_of[id] = static_cast<int>(k);
      f.airframe_of[id] = static_cast<int>(k) + 1;
    }
    f.quadrotors.push_back(g.quadrotor);
    f.controllers.push_back(g.controller);
  }
  return f;
}

std::string fleet_summary(const Fleet& fleet) {
  std::string out;
  for (std::size_t a = 0; a < fleet.quadrotors.size(); ++a) {
    std::vector<int> ids;
    for (std::size_t i = 0; i < fleet.airframe_of.size(); ++i)
      if (fleet.airframe_of[i] == static_cast<int>(a)) ids.push_back(static_cast<int>(i));
    if (ids.empty()) continue;
    out += (out.empty() ? "" : "; ") + airframe_name(fleet.quadrotors[a].airframe) + ": drone" +
           (ids.size() > 1 ? "s " : " ") + ranges_of(ids);
  }
  return out;
}

}  // namespace ddswarm::sim
