#include "common/agent_rejoin.hpp"

#include <exception>

#include "common/scenario.hpp"

namespace ddswarm {

double scenario_rejoin_after_s(const std::string& scenario_path) {
  double rejoin_after_s = kDefaultRejoinAfterS;
  try {
    load_scenario(scenario_path).section("agent").get("rejoin_after_s", rejoin_after_s);
  } catch (const std::exception&) {
    return kDefaultRejoinAfterS;
  }
  return rejoin_after_s;
}

}  // namespace ddswarm
