#include "agent/agent_app_config.hpp"

#include "common/config_error.hpp"

namespace ddswarm::agent {

namespace {
/// Every override names drones of the scenario.
void check_overrides(const AgentAppConfig& c) {
  for (std::size_t k = 0; k < c.agent.overrides.size(); ++k)
    for (int id : c.agent.overrides[k].ids)
      if (id >= c.scenario.drones)
        throw FieldError(
            "agent.overrides[" + std::to_string(k) + "].ids", c.agent.overrides[k].ids_text,
            "drone " + std::to_string(id) + " is not in the scenario (scenario.drones = " +
                std::to_string(c.scenario.drones) + ")");
}
}  // namespace

void AgentAppConfig::validate() const {
  scenario.validate();
  agent.validate();
  comm.validate();
  dds.validate();
  check_overrides(*this);
  if (drone_ids.empty()) throw FieldError("--id/--ids", "", "no drone to fly");
  for (int id : drone_ids)
    if (id < 0 || id >= scenario.drones)
      throw FieldError("--id/--ids", std::to_string(id),
                       "must be in [0, " + std::to_string(scenario.drones - 1) + "]");
}

AgentAppConfig load_agent_config(const std::string& path) {
  auto doc = load_scenario(path);
  AgentAppConfig c;
  doc.guard([&] {
    load(doc.section("scenario"), c.scenario);
    load(doc.section("agent"), c.agent);
    load(doc.section("comm"), c.comm);
    load(doc.section("dds"), c.dds);
    c.scenario.validate();
    c.agent.validate();
    c.comm.validate();
    c.dds.validate();
    check_overrides(c);
  });
  return c;
}

}  // namespace ddswarm::agent
