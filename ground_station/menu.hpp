#pragma once
// The ground station's console, after the thesis's (Fig. 9 and 10):
//
//   Please choose an option:
//   1: Takeoff
//   2: Move swarm by velocity and time
//   3: Change distance between drones
//   4: Land
//   5: Follow the leader
//   6: Task
//   0: Quit
//
// A status line (sim time, real-time factor, drones online, airborne,
// collisions) is printed before every menu. Numbers are checked before they
// are sent: a bad entry is re-asked with a one-line reason, a few times at
// most, then the option is abandoned. End of input (or the reader's
// interrupt, e.g. Ctrl-C) at any prompt quits.
#include <iosfwd>

#include "common/config_error.hpp"
#include "ground_station/commander.hpp"
#include "ground_station/line_reader.hpp"

namespace ddswarm::gs {

/// Limits on what the console accepts, and its defaults.
struct MenuOptions {
  double max_speed_mps = 10.0;          ///< m/s, limit on each velocity component typed, > 0
  double max_duration_s = 3600.0;       ///< s, longest move, > 0
  double min_distance_m = 0.5;          ///< m, smallest D_int accepted, > 0
  double max_distance_m = 50.0;         ///< m, largest D_int accepted, >= min_distance_m
  double max_altitude_m = 100.0;        ///< m, highest takeoff altitude, > 0
  double default_task_speed_mps = 0.8;  ///< m/s, offered by option 6 (thesis Sim 1), > 0
  double task_epsilon_m = 0.0;          ///< m, swarm-condition size for the task, 0 = agents'
  double teleop_step_mps = 1.0;         ///< m/s, leader speed per w/a/s/d/r/f key, > 0
  int max_attempts = 3;                 ///< bad entries per prompt before giving up, >= 1
  int max_drone_id = 9999;              ///< largest leader id when the drone count is unknown
  bool show_status = true;              ///< print the status line before each menu

  void validate() const;  ///< throws FieldError("menu.…")
};

/// Runs the console until the user quits (0) or input ends (or the reader is
/// interrupted). Every command's
/// result is printed to out; exceptions from the commander are reported and
/// the menu carries on. Leaving follow-the-leader (q or end of input) sends
/// hold() first. Returns 0 (the process exit code). Throws FieldError when
/// options fail validate().
int run_menu(Commander& commander, LineReader& reader, std::ostream& out,
             const MenuOptions& options = {});

/// The status line printed before each menu, e.g.
/// "[sim 12.3 s | x1.00 real time | drones 6/6 online | 6 airborne | 0 collisions | ...]".
std::string format_status(const SwarmStatus& s);

/// "rejected samples: 7 (non-finite 2, absurd 1, ..., agents 0)": what the
/// server and the agents refused, by reason; "rejected samples: unknown" when
/// nothing was heard yet.
std::string format_rejections(const SwarmStatus& s);

/// "commands: 1200 applied, 3 late (answered after their step)"; "" when no
/// server was heard.
std::string format_commands(const SwarmStatus& s);

}  // namespace ddswarm::gs
