#pragma once
// Loads a swarm-law plug-in: a shared library built against ddswarm/law.hpp
// that exports its factory with DDSWARM_LAW_PLUGIN.
#include <string>

#include "ddswarm/law.hpp"

namespace ddswarm::agent {

/// The factory of the plug-in at path (relative paths from the working
/// directory), loaded once per process and never unloaded: its laws' code
/// lives in it. Throws law::ParamError(field, path, why) when the file is
/// missing, is not a loadable library, lacks the plug-in's symbols, or was
/// built against another law API version.
law::MakeLaw plugin_factory(const std::string& path, const std::string& field);

}  // namespace ddswarm::agent
