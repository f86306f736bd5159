#include "agent/comm_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace ddswarm::agent {
namespace {

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ULL;

// SplitMix64's finaliser: a bijection with full avalanche.
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::uint64_t combine(std::uint64_t h, std::uint64_t v) { return mix64(mix64(h + kGolden) ^ v); }

// What a draw is for: each gets its own stream, so one effect's draws never
// shift another's.
enum Stream : std::uint64_t { kLoss = 1, kDelay, kNoise, kRange, kOwn };

// A SplitMix64 sequence from one key.
class Draws {
 public:
  explicit Draws(std::uint64_t key) : state_(key) {}
  std::uint64_t next() { return mix64(state_ += kGolden); }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  Eigen::Vector3d normal3() {
    const auto [a, b] = normal2();
    return {a, b, normal2().first};
  }
  double normal() { return normal2().first; }

 private:
  std::pair<double, double> normal2() {  // Box-Muller
    const double u1 = 1.0 - uniform();   // (0, 1]: log stays finite
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double a = 2.0 * std::numbers::pi * u2;
    return {r * std::cos(a), r * std::sin(a)};
  }
  std::uint64_t state_;
};

Draws draws(std::uint64_t root, std::uint64_t sender, std::uint64_t tick, Stream s) {
  return Draws(combine(combine(combine(root, sender), tick), s));
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

CommChannel::CommChannel(const CommConfig& c, std::uint64_t seed, int receiver_id, double tick_s)
    : cfg_(c), receiver_(receiver_id), tick_s_(tick_s) {
  cfg_.validate();
  if (!(tick_s > 0) || !std::isfinite(tick_s))
    throw std::invalid_argument("CommChannel: tick_s must be > 0, got " + to_text(tick_s));
  key_ = combine(combine(combine(0x636f6d6dULL /* "comm" */, seed), cfg_.seed_salt),
                 static_cast<std::uint64_t>(static_cast<std::int64_t>(receiver_id)));
}

void CommChannel::send(const PeerMessage& m, const Eigen::Vector3d& receiver_true_p,
                       std::uint64_t min_delay_ticks) {
  ++stats_.sent;
  const double true_distance = (m.sender_true_p - receiver_true_p).norm();
  if (cfg_.max_range_m > 0 && !(true_distance <= cfg_.max_range_m)) {
    ++stats_.out_of_range;
    return;
  }
  const auto sender = static_cast<std::uint64_t>(static_cast<std::int64_t>(m.sender));
  if (draws(key_, sender, m.tick_sent, kLoss).uniform() < cfg_.loss_probability) {
    ++stats_.lost;
    return;
  }
  const double delay_s =
      cfg_.latency_s + cfg_.jitter_s * draws(key_, sender, m.tick_sent, kDelay).uniform();
  // validate() bounds delay_s by 120 s: no overflow at any sensible tick_s.
  const auto delay = static_cast<std::uint64_t>(std::max(0LL, std::llround(delay_s / tick_s_)));

  Delivered d;
  d.sender = m.sender;
  d.tick_sent = m.tick_sent;
  d.tick_due = m.tick_sent + std::max(delay, min_delay_ticks);
  d.stamp_s = m.stamp_s;
  d.p_world = m.reported_p;
  if (cfg_.position_noise_sigma_m > 0)
    d.p_world += cfg_.position_noise_sigma_m * draws(key_, sender, m.tick_sent, kNoise).normal3();
  if (cfg_.range_measurements)
    d.measured_range_m =
        std::max(0.0, true_distance + cfg_.range_noise_sigma_m *
                                          draws(key_, sender, m.tick_sent, kRange).normal());
  if (last_delivered_tick_ && d.tick_due <= *last_delivered_tick_) ++stats_.late;
  queue_.emplace(Key{d.tick_due, d.sender, d.tick_sent, seq_++}, std::move(d));
}

std::vector<Delivered> CommChannel::deliver(std::uint64_t tick) {
  std::vector<Delivered> out;
  auto it = queue_.begin();
  for (; it != queue_.end() && std::get<0>(it->first) <= tick; ++it) out.push_back(it->second);
  queue_.erase(queue_.begin(), it);
  stats_.delivered += out.size();
  last_delivered_tick_ = std::max(tick, last_delivered_tick_.value_or(0));
  return out;
}

Eigen::Vector3d CommChannel::noisy_own_position(const Eigen::Vector3d& p,
                                                std::uint64_t tick) const {
  if (cfg_.own_position_noise_sigma_m <= 0) return p;
  // Its own stream tag keeps these draws apart from any message's.
  return p + cfg_.own_position_noise_sigma_m * draws(key_, ~std::uint64_t{0}, tick, kOwn).normal3();
}

ModelledPeerSource::ModelledPeerSource(const CommConfig& c, std::uint64_t seed, int self_id,
                                       double tick_s)
    : cfg_(c),
      self_(self_id),
      channel_(c, seed, self_id, tick_s),
      beacon_period_(c.beacon_period_ticks(tick_s)) {}

void ModelledPeerSource::set_tick(std::uint64_t tick, double t,
                                  const Eigen::Vector3d& self_true_p) {
  tick_ = tick;
  now_s_ = t;
  self_p_ = self_true_p;
}

void ModelledPeerSource::on_truth(double t, std::span<const PeerObservation> swarm) {
  if (t != now_s_) {
    tick_ = static_cast<std::uint64_t>(std::max(0LL, std::llround(t / channel_.tick_s())));
    now_s_ = t;
  }
  if (cfg_.source != PeerSourceType::kTruth) return;
  for (const auto& o : swarm) {
    if (o.id == self_) continue;
    if (!finite(o.p_world)) {
      ++rejected_;
      continue;
    }
    channel_.send({o.id, tick_, o.stamp_s, o.p_world, o.p_world}, self_p_);
  }
}

void ModelledPeerSource::on_beacon(const PeerMessage& m, const Eigen::Vector3d& receiver_true_p) {
  if (cfg_.source != PeerSourceType::kBeacons || m.sender == self_) return;
  if (!finite(m.reported_p) || !finite(m.sender_true_p) || !std::isfinite(m.stamp_s)) {
    ++rejected_;
    return;
  }
  channel_.send(m, receiver_true_p, 1);
}

void ModelledPeerSource::update() {
  for (auto& d : channel_.deliver(tick_)) {
    auto it = kept_.find(d.sender);
    if (it == kept_.end())
      kept_.emplace(d.sender, Kept{std::move(d), now_s_});
    else if (d.stamp_s > it->second.msg.stamp_s)
      it->second = Kept{std::move(d), now_s_};
  }
}

const std::vector<Eigen::Vector3d>& ModelledPeerSource::peers(double t) {
  update();
  peers_.clear();
  for (const auto& [id, k] : kept_)
    if (fresh(k, t)) peers_.push_back(k.msg.p_world);
  return peers_;
}

std::vector<PeerObservation> ModelledPeerSource::heard(double t) {
  update();
  std::vector<PeerObservation> out;
  for (const auto& [id, k] : kept_)
    if (fresh(k, t)) out.push_back({id, k.msg.p_world, k.msg.stamp_s});
  return out;
}

std::optional<double> ModelledPeerSource::range_to(int peer) {
  update();
  auto it = kept_.find(peer);
  if (it == kept_.end() || !fresh(it->second, now_s_)) return std::nullopt;
  return it->second.msg.measured_range_m;
}

PeerMessage ModelledPeerSource::beacon(std::uint64_t tick, double t,
                                       const Eigen::Vector3d& self_true_p) const {
  return {self_, tick, t, channel_.noisy_own_position(self_true_p, tick), self_true_p};
}

}  // namespace ddswarm::agent
