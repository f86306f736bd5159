#pragma once
// The configuration reference (docs/configuration.md) checked against the
// field lists (common/config_fields.hpp): a section's table must have a row
// for every field, with the field's default, unit and bounds, and no row for
// a scalar field that does not exist. Tests call this for each section, so
// the reference cannot drift from the code.
#include <string>
#include <vector>

#include "common/config_fields.hpp"

namespace ddswarm {

/// The mismatches (one line each; empty when the doc agrees) between rows and
/// the first table after the first heading of markdown that contains
/// heading (e.g. "### `comm:`"). A doc default is compared as a number where
/// both are numbers; a doc range cell must begin with the bounds' text; an
/// enum's every name must appear in its row.
std::vector<std::string> reference_mismatches(const std::string& markdown,
                                              const std::string& heading,
                                              const std::vector<FieldRow>& rows);

/// The text of docs/configuration.md in the source tree.
std::string configuration_reference();

}  // namespace ddswarm
