#include "sim_server/rival_arbiter.hpp"

#include <algorithm>
#include <utility>

namespace ddswarm::sim {

RivalArbiter::Move RivalArbiter::on_scene(std::int64_t other_ns, std::int64_t now_ns,
                                          bool mission_begun) {
  const std::int64_t own = published_ns_ != 0 ? published_ns_ : now_ns;
  if (!mission_begun && other_ns < own) return Move::kLeave;
  return std::exchange(said_, true) ? Move::kStay : Move::kStayAndSay;
}

bool RivalArbiter::leaves_for_status(bool mission_begun,
                                     const std::vector<std::uint32_t>& other_seqs) {
  return !mission_begun &&
         std::any_of(other_seqs.begin(), other_seqs.end(), [](std::uint32_t q) { return q != 0; });
}

}  // namespace ddswarm::sim
