#include "agent/comm_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "agent/comm_config.hpp"

using namespace ddswarm;
using namespace ddswarm::agent;

namespace {

constexpr double kTick = 0.02;  // 50 Hz control
// Two-sided 99.9 % normal quantile: the bound every statistical check uses.
constexpr double kZ999 = 3.29;
const Eigen::Vector3d kOrigin = Eigen::Vector3d::Zero();

PeerMessage message(int sender, std::uint64_t tick, const Eigen::Vector3d& p) {
  return {sender, tick, static_cast<double>(tick) * kTick, p, p};
}

struct Moments {
  double mean = 0, sd = 0;
};

Moments moments(const std::vector<double>& x) {
  Moments m;
  for (double v : x) m.mean += v;
  m.mean /= static_cast<double>(x.size());
  for (double v : x) m.sd += (v - m.mean) * (v - m.mean);
  m.sd = std::sqrt(m.sd / static_cast<double>(x.size() - 1));
  return m;
}

/// Loads and validates `text`; returns the ConfigError text, or "".
std::string error_of(const std::string& text) {
  try {
    auto doc = YamlDocument::parse(text, "s.yaml");
    CommConfig c;
    doc.guard([&] {
      load(doc.section("comm"), c);
      c.validate();
    });
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---- configuration ---------------------------------------------------------

TEST(CommConfig, DefaultsAreValidAndIdeal) {
  CommConfig c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_TRUE(c.ideal());
  EXPECT_EQ(c.source, PeerSourceType::kTruth);
  EXPECT_EQ(c.beacon_period_ticks(kTick), 5u);  // 10 Hz beacons at 50 Hz control
  c.latency_s = 0.01;
  EXPECT_FALSE(c.ideal());
}

TEST(CommConfig, ReadsEveryField) {
  auto doc = YamlDocument::parse(R"(
comm:
  source: beacons
  beacon_rate_hz: 25
  latency_s: 0.05
  jitter_s: 0.02
  loss_probability: 0.1
  position_noise_sigma_m: 0.3
  max_range_m: 30
  range_measurements: true
  range_noise_sigma_m: 0.05
  own_position_noise_sigma_m: 0.5
  peer_timeout_s: 0.8
  seed_salt: 7
)",
                                 "s.yaml");
  CommConfig c;
  load(doc.section("comm"), c);
  c.validate();
  EXPECT_EQ(c.source, PeerSourceType::kBeacons);
  EXPECT_EQ(c.beacon_rate_hz, 25);
  EXPECT_EQ(c.latency_s, 0.05);
  EXPECT_EQ(c.jitter_s, 0.02);
  EXPECT_EQ(c.loss_probability, 0.1);
  EXPECT_EQ(c.position_noise_sigma_m, 0.3);
  EXPECT_EQ(c.max_range_m, 30);
  EXPECT_TRUE(c.range_measurements);
  EXPECT_EQ(c.range_noise_sigma_m, 0.05);
  EXPECT_EQ(c.own_position_noise_sigma_m, 0.5);
  EXPECT_EQ(c.peer_timeout_s, 0.8);
  EXPECT_EQ(c.seed_salt, 7u);
  EXPECT_EQ(c.beacon_period_ticks(kTick), 2u);
}

TEST(CommConfig, BadValuesNameTheFieldAndLine) {
  EXPECT_EQ(error_of("comm:\n  loss_probability: 1.5\n"),
            "s.yaml:2: comm.loss_probability = 1.5: must be in [0, 1]");
  EXPECT_EQ(error_of("comm:\n  latency_s: -0.1\n"),
            "s.yaml:2: comm.latency_s = -0.1: must be in [0, 60]");
  EXPECT_EQ(error_of("comm:\n  beacon_rate_hz: 0\n"),
            "s.yaml:2: comm.beacon_rate_hz = 0: must be > 0");
  EXPECT_EQ(error_of("comm:\n  beacon_rate_hz: 2000\n"),
            "s.yaml:2: comm.beacon_rate_hz = 2000: must be <= 1000");
  EXPECT_EQ(error_of("comm:\n  peer_timeout_s: 0\n"),
            "s.yaml:2: comm.peer_timeout_s = 0: must be > 0");
  EXPECT_EQ(error_of("comm:\n  position_noise_sigma_m: -1\n"),
            "s.yaml:2: comm.position_noise_sigma_m = -1: must be >= 0");
  EXPECT_NE(error_of("comm:\n  source: radio\n").find("must be one of beacons|truth"),
            std::string::npos);
  EXPECT_NE(error_of("comm:\n  latency: 0.1\n").find("latency"), std::string::npos);
  // Beacons every 0.5 s with a 0.2 s timeout: every peer would flicker out.
  EXPECT_NE(error_of("comm:\n  source: beacons\n  beacon_rate_hz: 2\n  peer_timeout_s: 0.2\n")
                .find("comm.peer_timeout_s = 0.2: must be >= 1 / beacon_rate_hz"),
            std::string::npos);
  EXPECT_EQ(error_of("comm:\n  source: truth\n  beacon_rate_hz: 2\n  peer_timeout_s: 0.2\n"), "");
}

// ---- the channel's statistics ----------------------------------------------

TEST(CommChannel, LossRateLiesWithinItsBinomialBound) {
  CommConfig c;
  c.loss_probability = 0.2;
  CommChannel ch(c, 11, 0, kTick);
  const int n = 20000;
  for (int i = 0; i < n; ++i)
    ch.send(message(1 + i % 5, static_cast<std::uint64_t>(i / 5), {1, 0, 0}), kOrigin);
  const auto got = ch.deliver(n);
  const double lost = static_cast<double>(ch.stats().lost);
  const double bound = kZ999 * std::sqrt(n * 0.2 * 0.8);
  std::printf("[ stats    ] loss: %.0f of %d lost = %.4f (expected 0.2000 +- %.4f at 99.9 %%)\n",
              lost, n, lost / n, bound / n);
  EXPECT_NEAR(lost, n * 0.2, bound);
  EXPECT_EQ(got.size() + ch.stats().lost, static_cast<std::size_t>(n));
  EXPECT_EQ(ch.stats().delivered, got.size());

  // The extremes are exact.
  c.loss_probability = 1.0;
  CommChannel all(c, 11, 0, kTick);
  c.loss_probability = 0.0;
  CommChannel none(c, 11, 0, kTick);
  for (std::uint64_t k = 0; k < 1000; ++k) {
    all.send(message(1, k, {1, 0, 0}), kOrigin);
    none.send(message(1, k, {1, 0, 0}), kOrigin);
  }
  EXPECT_TRUE(all.deliver(2000).empty());
  EXPECT_EQ(none.deliver(2000).size(), 1000u);
}

TEST(CommChannel, DelaysMatchLatencyPlusUniformJitterInTicks) {
  CommConfig c;
  c.latency_s = 0.1;  // 5 ticks
  c.jitter_s = 0.2;   // + U[0, 10] ticks
  CommChannel ch(c, 3, 2, kTick);
  const int n = 20000;
  std::vector<double> delay;
  std::vector<int> bins(16, 0);
  for (std::uint64_t k = 0; k < n + 20; ++k) {
    if (k < n) ch.send(message(1, k, {1, 0, 0}), kOrigin);
    auto out = ch.deliver(k);
    for (std::size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].tick_due, k) << "delivered exactly at its due tick, never early or late";
      if (i > 0) {
        EXPECT_LE(out[i - 1].tick_sent, out[i].tick_sent) << "same due tick, same sender";
      }
      const auto d = static_cast<int>(k - out[i].tick_sent);
      ASSERT_GE(d, 5);
      ASSERT_LE(d, 15);
      delay.push_back(d);
      ++bins[d];
    }
  }
  ASSERT_EQ(delay.size(), static_cast<std::size_t>(n));
  EXPECT_EQ(ch.in_flight(), 0u);
  // round(5 + 10 U): ticks 6..14 have probability 0.1, the end ticks 5 and 15 half that.
  const Moments m = moments(delay);
  const double sd_expected = std::sqrt(100.0 / 12 + 1.0 / 12);
  std::printf(
      "[ stats    ] delay: mean %.4f ticks (expected 10 +- %.4f), sd %.4f (expected %.4f)\n",
      m.mean, kZ999 * sd_expected / std::sqrt(n), m.sd, sd_expected);
  EXPECT_NEAR(m.mean, 10.0, kZ999 * sd_expected / std::sqrt(n));
  EXPECT_NEAR(m.sd, sd_expected, 0.03 * sd_expected);
  std::printf("[ stats    ] delay bins 5..15:");
  for (int d = 5; d <= 15; ++d) {
    const double p = (d == 5 || d == 15) ? 0.05 : 0.1;
    // 11 bins: z = 4 keeps the family-wise bound near 99.9 %.
    EXPECT_NEAR(bins[d], n * p, 4.0 * std::sqrt(n * p * (1 - p))) << "bin " << d;
    std::printf(" %d", bins[d]);
  }
  std::printf("\n");
}

TEST(CommChannel, DeliversInDueTickThenSenderOrder) {
  CommConfig c;
  c.jitter_s = 0.1;
  CommChannel ch(c, 5, 0, kTick);
  for (std::uint64_t k = 0; k < 200; ++k)
    for (int s : {4, 2, 3, 1}) ch.send(message(s, k, {1, 0, 0}), kOrigin);
  const auto out = ch.deliver(1000);
  ASSERT_EQ(out.size(), 800u);
  for (std::size_t i = 1; i < out.size(); ++i) {
    const auto& a = out[i - 1];
    const auto& b = out[i];
    EXPECT_TRUE(std::tie(a.tick_due, a.sender, a.tick_sent) <
                std::tie(b.tick_due, b.sender, b.tick_sent));
  }
}

TEST(CommChannel, PositionAndRangeNoiseHaveTheirSigma) {
  CommConfig c;
  c.position_noise_sigma_m = 0.5;
  c.range_measurements = true;
  c.range_noise_sigma_m = 0.1;
  CommChannel ch(c, 21, 0, kTick);
  const int n = 20000;
  const Eigen::Vector3d p(3, 4, 0);  // 5 m away: range noise is never clamped at 0
  for (int i = 0; i < n; ++i)
    ch.send(message(1 + i % 3, static_cast<std::uint64_t>(i / 3), p), kOrigin);
  const auto out = ch.deliver(n);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(n));
  std::vector<double> err[3], range_err;
  int within_1sigma = 0;
  for (const auto& d : out) {
    for (int a = 0; a < 3; ++a) err[a].push_back(d.p_world[a] - p[a]);
    if (std::abs(d.p_world.x() - p.x()) < c.position_noise_sigma_m) ++within_1sigma;
    ASSERT_TRUE(d.measured_range_m);
    range_err.push_back(*d.measured_range_m - 5.0);
  }
  for (int a = 0; a < 3; ++a) {
    const Moments m = moments(err[a]);
    std::printf("[ stats    ] position noise axis %d: mean %+.4f m, sd %.4f m (sigma 0.5)\n", a,
                m.mean, m.sd);
    EXPECT_NEAR(m.mean, 0.0, kZ999 * 0.5 / std::sqrt(n));
    EXPECT_NEAR(m.sd, 0.5, 0.03 * 0.5);
  }
  // Gaussian, not merely the right variance: P(|e| < sigma) = 0.6827.
  EXPECT_NEAR(within_1sigma, n * 0.6827, kZ999 * std::sqrt(n * 0.6827 * 0.3173));
  const Moments r = moments(range_err);
  std::printf("[ stats    ] range noise: mean %+.5f m, sd %.5f m (sigma 0.1); P(|e|<sigma) %.4f\n",
              r.mean, r.sd, static_cast<double>(within_1sigma) / n);
  EXPECT_NEAR(r.mean, 0.0, kZ999 * 0.1 / std::sqrt(n));
  EXPECT_NEAR(r.sd, 0.1, 0.03 * 0.1);
  // Axes are independent.
  double cov = 0;
  for (int i = 0; i < n; ++i) cov += err[0][i] * err[1][i];
  EXPECT_NEAR(cov / n / 0.25, 0.0, kZ999 / std::sqrt(n));
}

TEST(CommChannel, OwnPositionNoiseIsFixedPerTickWithItsSigma) {
  CommConfig c;
  c.own_position_noise_sigma_m = 2.0;
  CommChannel ch(c, 8, 3, kTick);
  const Eigen::Vector3d p(10, -5, 2);
  EXPECT_EQ(ch.noisy_own_position(p, 42), ch.noisy_own_position(p, 42));
  EXPECT_NE(ch.noisy_own_position(p, 42), ch.noisy_own_position(p, 43));
  const int n = 20000;
  std::vector<double> e;
  for (int k = 0; k < n; ++k) e.push_back(ch.noisy_own_position(p, k).z() - p.z());
  const Moments m = moments(e);
  std::printf("[ stats    ] own-position noise: mean %+.4f m, sd %.4f m (sigma 2)\n", m.mean, m.sd);
  EXPECT_NEAR(m.mean, 0.0, kZ999 * 2.0 / std::sqrt(n));
  EXPECT_NEAR(m.sd, 2.0, 0.03 * 2.0);
  // Without noise the position is exact.
  CommChannel exact(CommConfig{}, 8, 3, kTick);
  EXPECT_EQ(exact.noisy_own_position(p, 42), p);
}

// ---- determinism -----------------------------------------------------------

namespace {

CommConfig everything_on() {
  CommConfig c;
  c.latency_s = 0.04;
  c.jitter_s = 0.1;
  c.loss_probability = 0.3;
  c.position_noise_sigma_m = 0.2;
  c.max_range_m = 12;
  c.range_measurements = true;
  return c;
}

/// Five senders circling a receiver at the origin for 500 ticks, some of them
/// out of range part of the time; every delivered message in order.
std::vector<Delivered> run(const CommConfig& c, std::uint64_t seed, bool reverse_sends = false) {
  CommChannel ch(c, seed, 0, kTick);
  std::vector<Delivered> all;
  for (std::uint64_t k = 0; k < 500; ++k) {
    for (int j = 0; j < 5; ++j) {
      const int s = reverse_sends ? 5 - j : 1 + j;
      const double a = 0.01 * static_cast<double>(k) + s;
      ch.send(message(s, k, {(4.0 + 2 * s) * std::cos(a), (4.0 + 2 * s) * std::sin(a), 1}),
              kOrigin);
    }
    for (auto& d : ch.deliver(k)) all.push_back(d);
  }
  return all;
}

bool same(const std::vector<Delivered>& a, const std::vector<Delivered>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].sender != b[i].sender || a[i].tick_sent != b[i].tick_sent ||
        a[i].tick_due != b[i].tick_due || a[i].stamp_s != b[i].stamp_s ||
        a[i].p_world != b[i].p_world || a[i].measured_range_m != b[i].measured_range_m)
      return false;
  return true;
}

}  // namespace

TEST(CommChannel, SameSeedSameRunOtherSeedOtherRun) {
  const CommConfig c = everything_on();
  const auto a = run(c, 1);
  ASSERT_GT(a.size(), 500u);
  EXPECT_TRUE(same(a, run(c, 1)));
  EXPECT_FALSE(same(a, run(c, 2)));
  CommConfig salted = c;
  salted.seed_salt = 1;
  EXPECT_FALSE(same(a, run(salted, 1)));
  // Beacons arrive in DDS order: the order of send() calls must not matter.
  EXPECT_TRUE(same(a, run(c, 1, true)));
}

TEST(CommChannel, EachEffectDrawsFromItsOwnStream) {
  // Switching noise on loses and delays exactly the same messages.
  CommConfig c = everything_on();
  c.position_noise_sigma_m = 0;
  c.range_measurements = false;
  const auto quiet = run(c, 4);
  const auto noisy = run(everything_on(), 4);
  ASSERT_EQ(quiet.size(), noisy.size());
  for (std::size_t i = 0; i < quiet.size(); ++i) {
    EXPECT_EQ(quiet[i].sender, noisy[i].sender);
    EXPECT_EQ(quiet[i].tick_sent, noisy[i].tick_sent);
    EXPECT_EQ(quiet[i].tick_due, noisy[i].tick_due);
  }
}

// ---- the peer source -------------------------------------------------------

TEST(ModelledPeerSource, DefaultsAreANoOp) {
  ModelledPeerSource model(CommConfig{}, 1, 0, kTick);
  TruthPeerSource truth(0);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> step(-0.1, 0.1);
  // The swarm as an agent hands it to every brain: drone 0's own entry too.
  std::vector<PeerObservation> swarm;
  for (int id = 0; id < 6; ++id) swarm.push_back({id, {4.0 * id, 1, 2}, 0});
  for (std::uint64_t k = 0; k < 300; ++k) {
    const double t = static_cast<double>(k) * kTick;
    for (auto& o : swarm) {
      o.p_world += Eigen::Vector3d(step(rng), step(rng), step(rng));
      o.stamp_s = t;
    }
    const Eigen::Vector3d self = swarm[0].p_world;
    model.set_tick(k, t, self);
    model.on_truth(t, swarm);
    truth.on_truth(t, swarm);
    ASSERT_EQ(truth.peers(t).size(), 5u) << "its own entry is no peer";
    ASSERT_EQ(model.peers(t), truth.peers(t)) << "tick " << k;  // bit for bit, same tick
    for (const auto& h : model.heard(t)) EXPECT_EQ(h.stamp_s, t);
    EXPECT_EQ(model.channel().noisy_own_position(self, k), self);
    EXPECT_FALSE(model.range_to(1));
  }
  EXPECT_EQ(model.channel().in_flight(), 0u);
  EXPECT_EQ(model.channel().stats().delivered, 300u * 5u);
}

TEST(ModelledPeerSource, OnTruthAloneKeepsTheTickFromSimTime) {
  CommConfig c;
  c.latency_s = 0.1;  // 5 ticks
  ModelledPeerSource model(c, 1, 0, kTick);
  for (std::uint64_t k = 0; k < 200; ++k) {
    const double t = static_cast<double>(k) * kTick;
    const std::vector<PeerObservation> others = {{1, {static_cast<double>(k), 0, 0}, t}};
    model.on_truth(t, others);  // no set_tick
    const auto h = model.heard(t);
    ASSERT_EQ(h.size(), k >= 5 ? 1u : 0u) << "tick " << k;
    if (k >= 5) {
      EXPECT_EQ(h[0].p_world.x(), static_cast<double>(k - 5));
    }
  }
}

TEST(ModelledPeerSource, APeerBeyondRangeIsNeverHeardOneInsideAlways) {
  CommConfig c;
  c.max_range_m = 10;
  c.range_measurements = true;
  c.range_noise_sigma_m = 0.05;
  ModelledPeerSource model(c, 9, 0, kTick);
  const Eigen::Vector3d self(1, 1, 2);
  int heard_inside = 0, heard_crossing = 0;
  for (std::uint64_t k = 0; k < 1000; ++k) {
    const double t = static_cast<double>(k) * kTick;
    // Peer 1 just outside, peer 2 just inside, peer 3 at the limit at tick 500, then beyond.
    const double x3 = 5.0 + 10.0 * static_cast<double>(k) / 1000.0;
    const std::vector<PeerObservation> others = {
        {1, self + Eigen::Vector3d(0, 10.01, 0), t},
        {2, self + Eigen::Vector3d(9.99, 0, 0), t},
        {3, self + Eigen::Vector3d(0, 0, x3), t},
    };
    model.set_tick(k, t, self);
    model.on_truth(t, others);
    for (const auto& h : model.heard(t)) {
      EXPECT_NE(h.id, 1) << "tick " << k;
      if (h.id == 2 && h.stamp_s == t) ++heard_inside;
      if (h.id == 3 && h.stamp_s == t) {
        EXPECT_LE(x3, 10.0);
        ++heard_crossing;
      }
    }
    ASSERT_TRUE(model.range_to(2));
    EXPECT_NEAR(*model.range_to(2), 9.99, 5 * 0.05);
    EXPECT_FALSE(model.range_to(1));
  }
  EXPECT_EQ(heard_inside, 1000);
  EXPECT_EQ(heard_crossing, 501);  // ticks 0..500: exactly at the limit still counts as in range
  EXPECT_EQ(model.channel().stats().out_of_range, 1000u + 499u);
}

TEST(ModelledPeerSource, PeersNotHeardForLongerThanTheTimeoutDropOut) {
  CommConfig c;
  c.source = PeerSourceType::kBeacons;
  c.beacon_rate_hz = 50;  // every tick
  c.peer_timeout_s = 0.5;
  ModelledPeerSource model(c, 2, 0, kTick);
  auto present = [&](double t, int id) {
    for (const auto& h : model.heard(t))
      if (h.id == id) return true;
    return false;
  };
  for (std::uint64_t k = 0; k < 300; ++k) {
    const double t = static_cast<double>(k) * kTick;
    model.set_tick(k, t, kOrigin);
    model.on_beacon(message(2, k, {0, 5, 0}), kOrigin);  // always talking
    if (k <= 100 || k >= 200)
      model.on_beacon(message(1, k, {5, 0, 0}), kOrigin);  // silent 101..199
    EXPECT_EQ(model.peers(t).size(), model.heard(t).size());
    EXPECT_EQ(present(t, 2), k >= 1) << "beacons take at least one tick";
    // Peer 1's last beacon (tick 100) is heard at tick 101, t = 2.02 s.
    // Tick 126 (exactly 0.5 s after it was heard) is left to floating point.
    if (k >= 1 && k <= 125) {
      EXPECT_TRUE(present(t, 1)) << "tick " << k;
    } else if (k >= 127 && k <= 200) {
      EXPECT_FALSE(present(t, 1)) << "tick " << k;
    } else if (k >= 201) {
      EXPECT_TRUE(present(t, 1)) << "back when it talks again, tick " << k;
    }
  }
}

TEST(ModelledPeerSource, ALateOlderMessageNeverReplacesANewerOne) {
  CommConfig c;
  c.source = PeerSourceType::kBeacons;
  ModelledPeerSource model(c, 1, 0, kTick);
  model.set_tick(10, 0.20, kOrigin);
  model.on_beacon(message(1, 9, {9, 0, 0}), kOrigin);
  ASSERT_EQ(model.peers(0.20).size(), 1u);
  EXPECT_EQ(model.peers(0.20)[0].x(), 9);
  // The beacon of tick 5 turns up only now (slow DDS): late, older, ignored.
  model.set_tick(11, 0.22, kOrigin);
  model.on_beacon(message(1, 5, {5, 0, 0}), kOrigin);
  EXPECT_EQ(model.peers(0.22)[0].x(), 9);
  EXPECT_EQ(model.heard(0.22)[0].stamp_s, 9 * kTick);
  EXPECT_EQ(model.channel().stats().late, 1u);
  EXPECT_EQ(model.channel().stats().delivered, 2u);
  model.set_tick(12, 0.24, kOrigin);
  model.on_beacon(message(1, 11, {11, 0, 0}), kOrigin);
  EXPECT_EQ(model.peers(0.24)[0].x(), 11);
}

TEST(ModelledPeerSource, JitterReordersMessagesButTheKeptOneOnlyGetsNewer) {
  CommConfig c;
  c.jitter_s = 0.2;  // 0..10 ticks: messages overtake each other
  ModelledPeerSource model(c, 6, 0, kTick);
  double last_stamp = -1;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    const double t = static_cast<double>(k) * kTick;
    const std::vector<PeerObservation> others = {{1, {static_cast<double>(k), 0, 0}, t}};
    model.set_tick(k, t, kOrigin);
    model.on_truth(t, others);
    for (const auto& h : model.heard(t)) {
      EXPECT_GE(h.stamp_s, last_stamp) << "tick " << k;
      EXPECT_EQ(h.p_world.x(), std::round(h.stamp_s / kTick)) << "position matches its stamp";
      EXPECT_LE(t - h.stamp_s, 10 * kTick + 1e-9);
      last_stamp = h.stamp_s;
    }
  }
  // Check the channel really did reorder: replay it and count overtakes.
  CommChannel ch(c, 6, 0, kTick);
  int overtakes = 0;
  std::uint64_t latest = 0;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    ch.send(message(1, k, {0, 0, 0}), kOrigin);
    for (const auto& d : ch.deliver(k)) {
      if (d.tick_sent < latest) ++overtakes;
      latest = std::max(latest, d.tick_sent);
    }
  }
  std::printf("[ stats    ] jitter 10 ticks: %d of 2000 messages overtaken by a newer one\n",
              overtakes);
  EXPECT_GT(overtakes, 500);
}

TEST(ModelledPeerSource, BeaconsCarryTheSendersOwnEstimateAtTheBeaconRate) {
  CommConfig c;
  c.source = PeerSourceType::kBeacons;  // 10 Hz at 50 Hz control: every 5 ticks
  c.own_position_noise_sigma_m = 0.3;
  ModelledPeerSource a(c, 3, 0, kTick), b(c, 3, 1, kTick);
  auto pa = [](std::uint64_t k) { return Eigen::Vector3d(0.01 * static_cast<double>(k), 0, 2); };
  auto pb = [](std::uint64_t k) { return Eigen::Vector3d(4, 0.02 * static_cast<double>(k), 2); };
  int beacons = 0;
  for (std::uint64_t k = 0; k < 500; ++k) {
    const double t = static_cast<double>(k) * kTick;
    a.set_tick(k, t, pa(k));
    b.set_tick(k, t, pb(k));
    a.on_truth(t, {});  // beacons: the truth is not a source
    if (b.beacon_due(k)) {
      ++beacons;
      const PeerMessage m = b.beacon(k, t, pb(k));
      EXPECT_EQ(m.reported_p, b.channel().noisy_own_position(pb(k), k)) << "what b's law sees";
      a.on_beacon(m, pa(k));
      b.on_beacon(m, pb(k));  // a drone hears its own beacon on the topic: ignored
    }
    const auto h = a.heard(t);
    if (k == 0) {
      EXPECT_TRUE(h.empty()) << "a beacon takes at least one tick";
      continue;
    }
    ASSERT_EQ(h.size(), 1u);
    const auto sent = static_cast<std::uint64_t>(std::llround(h[0].stamp_s / kTick));
    EXPECT_EQ(sent % 5, 0u);
    EXPECT_LE(k - sent, 5u);
    EXPECT_GE(k - sent, 1u);
    EXPECT_EQ(h[0].p_world, b.channel().noisy_own_position(pb(sent), sent));
    EXPECT_TRUE(b.heard(t).empty());
  }
  EXPECT_EQ(beacons, 100);
  // NaN beacons are refused and counted.
  PeerMessage bad = b.beacon(500, 10.0, pb(500));
  bad.reported_p.x() = std::nan("");
  a.on_beacon(bad, pa(500));
  EXPECT_EQ(a.rejected(), 1u);
}
