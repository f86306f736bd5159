// A process that leaves DDS and joins again (an agent re-joining) must come
// back as a new participant, not under the GUID it left with.
#include <gtest/gtest.h>

#include <algorithm>

#include "common/participant.hpp"
#include "common/process.hpp"

namespace ddswarm {
namespace {

eprosima::fastrtps::rtps::GuidPrefix_t join_and_leave(const DdsConfig& cfg) {
  Participant p(cfg, "participant_test");
  return p.raw()->guid().guidPrefix;
}

TEST(Participant, EveryJoinOfAProcessHasItsOwnGuid) {
  DdsConfig cfg;
  cfg.domain_id = 20 + static_cast<int>(random_instance() % 60);
  cfg.participant_id = 117;  // as an agent of a 128-drone swarm: the same id at every join
  const auto first = join_and_leave(cfg);
  const auto second = join_and_leave(cfg);
  const auto third = join_and_leave(cfg);
  EXPECT_NE(first, second);
  EXPECT_NE(second, third);
  EXPECT_NE(first, third);
  // Still one host and one process to Fast DDS (vendor, host and process
  // bytes), and the participant id where Fast DDS puts it.
  EXPECT_TRUE(std::equal(first.value, first.value + 9, second.value));
  EXPECT_TRUE(std::equal(first.value, first.value + 9, third.value));
}

TEST(Participant, IncarnationPrefixKeepsHostAndProcess) {
  eprosima::fastrtps::rtps::GuidPrefix_t first;
  for (int i = 0; i < 12; ++i) first.value[i] = static_cast<eprosima::fastrtps::rtps::octet>(i < 9 ? 0x10 + i : 0);
  const auto p = incarnation_prefix(first, 0x030201);
  EXPECT_TRUE(std::equal(first.value, first.value + 9, p.value));
  EXPECT_EQ(p.value[9], 0x01);
  EXPECT_EQ(p.value[10], 0x02);
  EXPECT_EQ(p.value[11], 0x03);
  EXPECT_NE(incarnation_prefix(first, 1), incarnation_prefix(first, 2));
}

}  // namespace
}  // namespace ddswarm
