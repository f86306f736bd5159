// The inline swarm-state decoder against the generated code: the same
// sample from the same bytes, in either byte order, and nothing from bytes
// the generated code would refuse or that break the IDL's bounds.
#include "common/swarm_state_cdr.hpp"
#include "common/convert.hpp"

#include <fastcdr/exceptions/Exception.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "common/topics.hpp"
#include "ddswarm_idl_text.hpp"

using namespace ddswarm;
using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

/// The generated code's reading of the bytes, or nothing where it refuses them.
std::optional<msg::SwarmState> generated(const std::vector<std::uint8_t>& bytes) {
  msg::SwarmStatePubSubType t;
  Payload p(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), p.data);
  p.length = static_cast<std::uint32_t>(bytes.size());
  msg::SwarmState out;
  try {
    if (t.deserialize(&p, &out)) return out;
  } catch (const eprosima::fastcdr::exception::Exception&) {
  }
  return std::nullopt;
}

std::optional<msg::SwarmState> inline_decoded(const std::vector<std::uint8_t>& bytes) {
  msg::SwarmState out;
  if (decode_swarm_state(bytes.data(), bytes.size(), out)) return out;
  return std::nullopt;
}

/// Two samples are the same when they serialize to the same bytes (NaN included).
void expect_same(const msg::SwarmState& a, const msg::SwarmState& b, const std::string& what) {
  EXPECT_EQ(encode_swarm_state(a), encode_swarm_state(b)) << what;
}

msg::SwarmState random_state(std::mt19937& rng, int drones) {
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  std::uniform_int_distribution<int> byte(0, 255);
  const double specials[] = {
      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), -0.0,
      std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min()};
  auto value = [&] { return rng() % 17 == 0 ? specials[rng() % 5] : u(rng); };
  auto vec = [&] {
    msg::Vec3 v;
    v.x(value());
    v.y(value());
    v.z(value());
    return v;
  };
  msg::SwarmState s;
  s.tick(rng() * 4096ULL + rng());
  s.sim_time_s(value());
  for (int i = 0; i < drones; ++i) {
    msg::DroneState d;
    d.drone_id(static_cast<std::uint16_t>(rng()));
    d.tick(rng());
    d.sim_time_s(value());
    d.position(vec());
    msg::Quat q;
    q.w(value());
    q.x(value());
    q.y(value());
    q.z(value());
    d.orientation(q);
    d.velocity(vec());
    d.angular_velocity(vec());
    for (auto& m : d.motor_speed_rad_s()) m = static_cast<float>(value());
    d.collisions_obstacle(rng());
    d.collisions_drone(rng());
    d.collisions_ground(rng());
    d.flags(static_cast<std::uint16_t>(rng()));
    d.phase(static_cast<std::uint8_t>(byte(rng)));
    d.command_age_s(static_cast<float>(value()));
    s.drones().push_back(d);

    msg::DistanceScan sc;
    sc.drone_id(static_cast<std::uint16_t>(i));
    sc.tick(rng());
    sc.sim_time_s(value());
    sc.max_range_m(static_cast<float>(value()));
    const int rays = static_cast<int>(rng() % 257);
    // On the wire the sequences' lengths are independent: sometimes one is short.
    const int elevations = rng() % 8 == 0 ? static_cast<int>(rng() % (rays + 1)) : rays;
    for (int k = 0; k < rays; ++k) {
      sc.angle_body_rad().push_back(static_cast<float>(value()));
      if (k < elevations) sc.elevation_body_rad().push_back(static_cast<float>(value()));
      sc.range_m().push_back(static_cast<float>(value()));
      sc.hit().push_back(static_cast<std::uint8_t>(byte(rng)));
    }
    if (rng() % 3 != 0) s.scans().push_back(sc);

    if (rng() % 2 == 0) {
      msg::Beacon b;
      b.drone_id(static_cast<std::uint16_t>(i));
      b.tick(rng());
      b.stamp_s(value());
      b.position(vec());
      b.velocity(vec());
      b.true_position(vec());
      s.beacons().push_back(b);
    }
  }
  const int commands = static_cast<int>(rng() % 9);
  for (int k = 0; k < commands; ++k) {
    msg::MissionCommand c;
    c.seq(rng());
    c.type(static_cast<std::uint8_t>(byte(rng)));
    c.target(static_cast<std::int32_t>(rng()));
    c.velocity(vec());
    c.duration_s(value());
    c.value(value());
    c.leader_id(static_cast<std::int32_t>(rng()));
    c.epsilon_m(value());
    std::string issuer(rng() % 65, 'a');
    for (auto& ch : issuer) ch = static_cast<char>('a' + rng() % 26);
    c.issuer() = issuer.c_str();
    c.issuer_instance(rng() * 65536ULL);
    c.server_instance(rng());
    c.apply_tick(rng());
    s.recent_commands().push_back(c);
  }
  return s;
}

}  // namespace

TEST(SwarmStateCdr, DecodesWhatTheGeneratedCodeDecodesInEitherByteOrder) {
  std::mt19937 rng(20261129);
  int checked = 0;
  for (int drones : {0, 1, 6, 16, 128, 300, 1024}) {
    for (int round = 0; round < 5; ++round) {
      const msg::SwarmState s = random_state(rng, drones);
      for (bool big : {false, true}) {
        const auto bytes = encode_swarm_state(s, big);
        const auto gen = generated(bytes);
        ASSERT_TRUE(gen.has_value()) << drones << " drones";
        const auto fast = inline_decoded(bytes);
        ASSERT_TRUE(fast.has_value())
            << drones << " drones, " << (big ? "big" : "little") << " endian";
        expect_same(*fast, *gen, std::to_string(drones) + " drones");
        expect_same(*fast, s, "the sample sent");
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 70);
}

TEST(SwarmStateCdr, RefusesEveryTruncation) {
  std::mt19937 rng(7);
  const auto bytes = encode_swarm_state(random_state(rng, 6));
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    const std::vector<std::uint8_t> cut(bytes.begin(),
                                        bytes.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_FALSE(inline_decoded(cut).has_value()) << n << " of " << bytes.size() << " bytes";
    EXPECT_FALSE(generated(cut).has_value()) << n << " of " << bytes.size() << " bytes (generated)";
  }
  EXPECT_TRUE(inline_decoded(bytes).has_value());
}

TEST(SwarmStateCdr, WhatItAcceptsFromCorruptBytesTheGeneratedCodeReadsAlike) {
  std::mt19937 rng(11);
  const auto clean = encode_swarm_state(random_state(rng, 16));
  int accepted = 0, refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto bytes = clean;
    for (int k = 0, flips = 1 + static_cast<int>(rng() % 3); k < flips; ++k)
      bytes[rng() % bytes.size()] = static_cast<std::uint8_t>(rng());
    const auto fast = inline_decoded(bytes);
    if (!fast) {
      ++refused;
      continue;
    }
    ++accepted;
    const auto gen = generated(bytes);
    ASSERT_TRUE(gen.has_value()) << "trial " << trial
                                 << ": accepted bytes the generated code refuses";
    expect_same(*fast, *gen, "trial " + std::to_string(trial));
  }
  EXPECT_GT(accepted, 1000);  // most flips land in values, which decode
  EXPECT_GT(refused, 0);      // some land in lengths
}

// Found by fuzz_swarm_state: an encapsulation kind with a bit beyond byte
// order and parameter list, which Fast CDR refuses ("Unexpected CDR type"),
// as it does a first byte other than zero.
TEST(SwarmStateCdr, ReadsTheEncapsulationAsFastCdrDoes) {
  std::mt19937 rng(13);
  const auto clean = encode_swarm_state(random_state(rng, 2));
  for (int kind = 0; kind < 256; ++kind) {
    for (int first : {0x00, 0xcf}) {
      auto bytes = clean;
      bytes[0] = static_cast<std::uint8_t>(first);
      bytes[1] = static_cast<std::uint8_t>(kind);
      const auto fast = inline_decoded(bytes);
      const auto gen = generated(bytes);
      EXPECT_EQ(fast.has_value(), gen.has_value()) << "encapsulation " << first << " " << kind;
      if (fast && gen) expect_same(*fast, *gen, "encapsulation " + std::to_string(kind));
    }
  }
}

TEST(SwarmStateCdr, RefusesASequenceBeyondItsBound) {
  std::mt19937 rng(3);
  msg::SwarmState s = random_state(rng, 1);
  s.recent_commands().resize(9);  // sequence<MissionCommand, 8>
  EXPECT_FALSE(inline_decoded(encode_swarm_state(s)).has_value());
  s.recent_commands().resize(8);
  EXPECT_TRUE(inline_decoded(encode_swarm_state(s)).has_value());
  s.drones().resize(1025);  // sequence<DroneState, 1024>
  EXPECT_FALSE(inline_decoded(encode_swarm_state(s)).has_value());
}

TEST(SwarmStateCdr, TheTopicsTypeSupportCountsWhatItRefuses) {
  std::mt19937 rng(5);
  const auto bytes = encode_swarm_state(random_state(rng, 6));
  Topic<msg::SwarmState>::PubSub support;
  Payload p(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), p.data);
  p.length = static_cast<std::uint32_t>(bytes.size());
  msg::SwarmState out;
  const auto before = malformed_samples().load();
  EXPECT_TRUE(support.deserialize(&p, &out));
  EXPECT_EQ(out.drones().size(), 6u);
  EXPECT_EQ(malformed_samples().load(), before);
  p.length = static_cast<std::uint32_t>(bytes.size() / 2);
  EXPECT_FALSE(support.deserialize(&p, &out));
  EXPECT_EQ(malformed_samples().load(), before + 1);
}

TEST(SwarmStateCdr, AFullScanOf256RaysRoundTripsAndA257thIsRefused) {
  msg::SwarmState s;
  s.tick(42);
  msg::DistanceScan sc;
  sc.drone_id(0);
  sc.max_range_m(6);
  for (int k = 0; k < 256; ++k) {  // 8 rows of 32, as the server lays them out
    sc.angle_body_rad().push_back(static_cast<float>(2 * M_PI * (k % 32) / 32));
    sc.elevation_body_rad().push_back(static_cast<float>(0.1 * (k / 32) - 0.35));
    sc.range_m().push_back(static_cast<float>(0.5 + 0.01 * k));
    sc.hit().push_back(static_cast<std::uint8_t>(k % 2));
  }
  s.scans().push_back(sc);
  s.drones().resize(1);
  const auto decoded = inline_decoded(encode_swarm_state(s));
  ASSERT_TRUE(decoded.has_value());
  const auto& d = decoded->scans().at(0);
  ASSERT_EQ(d.elevation_body_rad().size(), 256u);
  EXPECT_EQ(d.elevation_body_rad(), sc.elevation_body_rad());
  EXPECT_EQ(d.angle_body_rad(), sc.angle_body_rad());
  EXPECT_EQ(d.range_m(), sc.range_m());
  EXPECT_EQ(d.hit(), sc.hit());
  EXPECT_EQ(scan_problem(d), "");
  s.scans()[0].elevation_body_rad().push_back(0);  // sequence<float, 256>
  EXPECT_FALSE(inline_decoded(encode_swarm_state(s)).has_value());
}

// docs/configuration.md's figures: what every drone adds to each tick's SwarmState.
TEST(SwarmStateCdr, EachDroneAddsItsStateAndItsScanOfThirteenBytesARay) {
  auto size = [](int drones, int rays) {
    msg::SwarmState s;
    for (int i = 0; i < drones; ++i) {
      msg::DroneState d;
      d.drone_id(static_cast<std::uint16_t>(i));
      s.drones().push_back(d);
      msg::DistanceScan sc;
      sc.drone_id(static_cast<std::uint16_t>(i));
      sc.angle_body_rad().assign(rays, 0);
      sc.elevation_body_rad().assign(rays, 0);
      sc.range_m().assign(rays, 0);
      sc.hit().assign(rays, 0);
      s.scans().push_back(sc);
    }
    return static_cast<double>(encode_swarm_state(s).size());
  };
  // Give or take a byte of alignment padding.
  EXPECT_NEAR((size(64, 0) - size(0, 0)) / 64, 156.0 + 44, 1);  // a state, and an empty scan
  EXPECT_NEAR((size(64, 8) - size(0, 8)) / 64, 304.0, 1);       // the ring
  EXPECT_NEAR((size(64, 40) - size(0, 40)) / 64, 720.0, 1);     // 5 rows x 8
  EXPECT_NEAR((size(64, 256) - size(0, 256)) / 64, 3528.0, 1);
}

TEST(SwarmStateCdr, ARecordingFromBeforeElevationsReadsAsALevelRing) {
  std::mt19937 rng(17);
  msg::SwarmState s = random_state(rng, 3);
  for (auto& sc : s.scans()) {
    sc.angle_body_rad().resize(std::min<std::size_t>(sc.angle_body_rad().size(), 64));
    sc.range_m().resize(sc.angle_body_rad().size());
    sc.hit().resize(sc.angle_body_rad().size());
    sc.elevation_body_rad().clear();
  }
  const auto old = encode_swarm_state(s, false, ScanLayout::kRing64);
  msg::SwarmState out;
  EXPECT_FALSE(decode_swarm_state(old.data(), old.size(), out))
      << "the old layout read as the new one";
  ASSERT_TRUE(decode_swarm_state(old.data(), old.size(), out, ScanLayout::kRing64));
  ASSERT_EQ(out.scans().size(), s.scans().size());
  for (std::size_t i = 0; i < s.scans().size(); ++i) {
    EXPECT_EQ(out.scans()[i].range_m(), s.scans()[i].range_m());
    EXPECT_EQ(out.scans()[i].elevation_body_rad(),
              std::vector<float>(s.scans()[i].range_m().size(), 0.0f));
  }
  // Which layout a recording has, its schema (the IDL text it was written with) says.
  EXPECT_EQ(scan_layout_of(kIdlText), ScanLayout::kCurrent);
  EXPECT_EQ(scan_layout_of("struct DistanceScan {\n  sequence<float, 64> angle_body_rad;\n};"),
            ScanLayout::kRing64);
  EXPECT_EQ(scan_layout_of(""), ScanLayout::kCurrent);
}
