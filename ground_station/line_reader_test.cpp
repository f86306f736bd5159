#include "ground_station/line_reader.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <sstream>

namespace ddswarm::gs {
namespace {

TEST(LineReader, ReadsPlainLinesAndEchoesThemAfterThePrompt) {
  std::istringstream in("takeoff\r\n  2 \nlast");
  std::ostringstream out;
  LineReader r(in, out);
  EXPECT_FALSE(r.interactive());
  EXPECT_EQ(r.read("> "), "takeoff");
  EXPECT_EQ(r.read("> "), "  2 ");
  EXPECT_EQ(r.read("> "), "last");  // a final line without a newline still counts
  EXPECT_EQ(r.read("> "), std::nullopt);
  EXPECT_EQ(r.read("> "), std::nullopt);  // and stays at the end
  EXPECT_EQ(out.str(), "> takeoff\n>   2 \n> last\n> \n> \n");
}

TEST(LineReader, EmptyInputIsEndOfInput) {
  std::istringstream in("");
  std::ostringstream out;
  LineReader r(in, out);
  EXPECT_EQ(r.read("x: "), std::nullopt);
}

TEST(LineReader, InterruptEndsReading) {
  std::istringstream in("a\nb\nc\n");
  std::ostringstream out;
  LineReader r(in, out);
  bool stop = false;
  r.set_interrupt([&] { return stop; });
  EXPECT_EQ(r.read("> "), "a");
  EXPECT_FALSE(r.interrupted());
  stop = true;
  EXPECT_EQ(r.read("> "), std::nullopt);
  EXPECT_TRUE(r.interrupted());
  stop = false;
  EXPECT_EQ(r.read("> "), "b");  // the predicate decides, not a latch
  EXPECT_FALSE(r.interrupted());
}

TEST(LineReader, PlainModeNeverUsesTheTerminal) {
  // Under ctest stdin is not a terminal, and kPlain forces plain reads anyway.
  std::ostringstream out;
  LineReader r(std::cin, out, LineReader::Mode::kPlain);
  EXPECT_FALSE(r.interactive());
}

}  // namespace
}  // namespace ddswarm::gs
