#include "recorder/sequence_gaps.hpp"

#include <gtest/gtest.h>

namespace ddswarm::gs {
namespace {

SequenceGaps::WriterId writer(std::uint8_t k) {
  SequenceGaps::WriterId w{};
  w[15] = k;
  return w;
}

TEST(SequenceGaps, CountsWhatEachWriterSkipped) {
  SequenceGaps g;
  for (std::uint64_t s : {7, 8, 11, 12})
    g.received(writer(1), s);  // joined at 7: owed nothing before; 9, 10 lost
  for (std::uint64_t s : {1, 2, 6}) g.received(writer(2), s);  // its own numbers: 3, 4, 5 lost
  EXPECT_EQ(g.missed(), 5u);
  EXPECT_EQ(g.writers(), 2u);
}

TEST(SequenceGaps, AGapFilledLaterIsNoLoss) {
  SequenceGaps g;
  for (std::uint64_t s : {1, 2, 5, 6}) g.received(writer(1), s);
  EXPECT_EQ(g.missed(), 2u);
  g.received(writer(1), 4);  // a repair after a newer sample of another instance
  g.received(writer(1), 3);
  EXPECT_EQ(g.missed(), 0u);
  g.received(writer(3), 10);
  g.received(writer(3), 9);  // older than the first received: the span grows down
  EXPECT_EQ(g.missed(), 0u);
}

TEST(SequenceGaps, ADuplicateIsRefusedAndNotCounted) {
  SequenceGaps g;
  for (std::uint64_t s : {10, 11, 12, 20}) EXPECT_TRUE(g.received(writer(1), s));
  EXPECT_EQ(g.missed(), 7u);  // 13-19
  // A reader that joined again gets the writer's transient-local history once more.
  for (std::uint64_t s : {10, 11, 12, 20}) EXPECT_FALSE(g.received(writer(1), s));
  EXPECT_EQ(g.missed(), 7u);
  EXPECT_TRUE(g.received(writer(1), 15));  // a hole filled in its middle splits it
  EXPECT_FALSE(g.received(writer(1), 15));
  EXPECT_EQ(g.missed(), 6u);
  for (std::uint64_t s : {13, 19, 14, 16, 17, 18}) EXPECT_TRUE(g.received(writer(1), s));
  EXPECT_EQ(g.missed(), 0u);
  for (std::uint64_t s = 10; s <= 20; ++s) EXPECT_FALSE(g.received(writer(1), s)) << s;
  EXPECT_TRUE(g.received(writer(1), 8));  // below the first: new, and 9 is owed now
  EXPECT_EQ(g.missed(), 1u);
  EXPECT_TRUE(g.received(writer(2), 12));  // another writer's numbers are its own
}

}  // namespace
}  // namespace ddswarm::gs
