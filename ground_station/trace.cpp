#include "ground_station/trace.hpp"

#include <atomic>
#include <cstring>
#include <mutex>
#include <stdexcept>

#include "common/participant.hpp"

namespace ddswarm::gs {

struct SwarmTrace::Impl {
  FILE* f;
  int every;
  std::atomic<long> rows{0};
  std::mutex mu;
  Participant dds;
  Impl(const DdsConfig& d, const std::string& path, int e)
      : f(std::fopen(path.c_str(), "w")), every(std::max(1, e)), dds(d, "ddswarm-trace") {
    if (!f) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
    std::fprintf(f, "tick,sim_time_s,drone,x,y,z,vx,vy,vz,phase,flags,collisions\n");
    dds.reader<msg::SwarmState>([this](const msg::SwarmState& s, const fdds::SampleInfo&) {
      if (s.tick() % every) return;
      std::lock_guard<std::mutex> lock(mu);
      for (const auto& d : s.drones()) {
        std::fprintf(f, "%llu,%.3f,%u,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u,%u,%u\n",
                     static_cast<unsigned long long>(s.tick()), s.sim_time_s(), d.drone_id(),
                     d.position().x(), d.position().y(), d.position().z(), d.velocity().x(),
                     d.velocity().y(), d.velocity().z(), d.phase(), d.flags(),
                     d.collisions_obstacle() + d.collisions_drone() + d.collisions_ground());
        ++rows;
      }
    });
  }
  ~Impl() {
    std::lock_guard<std::mutex> lock(mu);
    std::fclose(f);
  }
};

SwarmTrace::SwarmTrace(const DdsConfig& dds, const std::string& path, int every)
    : impl_(std::make_unique<Impl>(dds, path, every)) {}
SwarmTrace::~SwarmTrace() = default;
long SwarmTrace::rows() const { return impl_->rows; }

}  // namespace ddswarm::gs
