#pragma once
// Checking a scenario before anything starts. Each process that will read a
// scenario reads it first as it will, with --check (ddswarm-sim,
// ddswarm-agent: load and validate, print one line, exit 0 or 2, no DDS), so
// a bad value stops a launch or an experiment at once, with nothing started,
// instead of each of its processes printing the error and dying. The readers
// are run, not linked: their configuration is theirs (dependencies point from
// the process folders to common/, never across).
#include <string>
#include <vector>

#include "launcher/launcher.hpp"

namespace ddswarm::gs {

/// The one line that tells why a check failed: the last line of its output
/// holding ": error: " ("ddswarm-agent: error: FILE:LINE: key = value: reason"),
/// or else how it ended and what it printed, on one line.
std::string check_error_line(const ChildExit& e, const std::string& output);

/// Runs the checks (each argv holds --check), as many at once as there are
/// cores, and waits for them all. Returns "" when each exited 0, or else the check_error_line of
/// the first, in the order given, that did not. Throws std::runtime_error when one cannot start.
std::string first_check_error(const std::vector<ChildSpec>& checks);

}  // namespace ddswarm::gs
