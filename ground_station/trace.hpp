#pragma once
// Writes the swarm's state to CSV as it flies: one row per drone per traced tick.
#include <cstdio>
#include <memory>
#include <string>

#include "common/dds_config.hpp"

namespace ddswarm::gs {

class SwarmTrace {
 public:
  /// every: keep one tick in `every`. Throws std::runtime_error if path cannot be written.
  SwarmTrace(const DdsConfig& dds, const std::string& path, int every);
  ~SwarmTrace();
  long rows() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::gs
