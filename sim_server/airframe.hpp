#pragma once
// Which airframe each drone flies. The `quadrotor:` section names the
// airframe of every drone (a preset, QuadrotorParams::preset, with the
// section's other keys over it) and `controller:` goes over that airframe's
// gains (ControllerConfig::preset). `quadrotor.groups` gives some drones
// another airframe, so one swarm mixes them:
//
//   quadrotor:
//     airframe: generic          # every drone not in a group
//     groups:
//       - ids: "0-2"             # the id-range syntax of --ids (common/id_ranges.hpp)
//         airframe: crazyflie
//         quadrotor: {mass_kg: 0.030}   # optional: over the preset
//         controller: {vel_p_xy: 2.5}   # optional: over the preset's gains
//
// Pure: no I/O beyond the YAML section it is handed.
#include <string>
#include <vector>

#include "common/yaml_section.hpp"
#include "sim_server/flight_controller.hpp"
#include "sim_server/quadrotor.hpp"

namespace ddswarm::sim {

/// Drones that fly another airframe than the `quadrotor:` one.
struct AirframeGroup {
  std::string ids;              ///< drone ids, e.g. "0-2,5"
  QuadrotorParams quadrotor;    ///< the preset with the group's overrides
  ControllerConfig controller;  ///< the preset's gains with the group's overrides
};

/// The airframes of a swarm and which one each drone flies.
struct Fleet {
  std::vector<QuadrotorParams> quadrotors;    ///< [0]: the `quadrotor:` airframe, then each group's
  std::vector<ControllerConfig> controllers;  ///< one per quadrotors entry
  std::vector<int> airframe_of;               ///< per drone, an index into quadrotors
};

/// Reads section `quadrotor` (with its groups): q is the section's airframe
/// with its overrides and c becomes that airframe's preset gains, for the
/// `controller:` section to go over. Unknown keys and airframes throw
/// ConfigError naming file, line, field and value.
void load_airframes(YamlSection s, QuadrotorParams& q, ControllerConfig& c,
                    std::vector<AirframeGroup>& groups);

/// Every drone's airframe: drones in a group fly its airframe, the others q.
/// Throws FieldError "quadrotor.groups[k]...." for a bad group: ids that do
/// not parse or lie outside [0, drones), a drone in two groups, or a bad
/// value of the group's airframe or gains.
Fleet make_fleet(const QuadrotorParams& q, const ControllerConfig& c,
                 const std::vector<AirframeGroup>& groups, int drones);

/// "generic: drones 3-5; crazyflie: drones 0-2" (each airframe and its drones).
std::string fleet_summary(const Fleet& fleet);

}  // namespace ddswarm::sim
