#include "common/config_fields.hpp"

#include <gtest/gtest.h>

#include "common/config_reference.hpp"

using namespace ddswarm;

namespace {

enum class Mode { kFast, kSlow };

/// A config struct as every component writes one.
struct ToyConfig {
  Mode mode = Mode::kSlow;
  double speed_mps = 2.5;
  int retries = 3;
  bool loud = false;
  double timeout_s = 0;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<Mode> kModes{{"fast", Mode::kFast}, {"slow", Mode::kSlow}};
    v.choice("mode", c.mode, kModes, {"", any(), "how it goes"});
    v.field("speed_mps", c.speed_mps, {"m/s", positive(), "how fast"});
    v.field("retries", c.retries, {"", in(0, 10), "how often"});
    v.field("loud", c.loud, {"", any(), "whether it logs"});
    v.field("timeout_s", c.timeout_s, {"s", zero_or(2, 60), "give up after; 0 = never"});
  }
};

ToyConfig load_toy(const std::string& yaml) {
  auto doc = YamlDocument::parse(yaml, "toy.yaml");
  ToyConfig c;
  doc.guard([&] {
    YamlSection s = doc.section("toy");
    FieldLoader l(s);
    ToyConfig::fields(c, l);
    s.finish();
    FieldChecker check("toy");
    ToyConfig::fields(c, check);
  });
  return c;
}

std::string error_of(const std::string& yaml) {
  try {
    load_toy(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* kDoc = R"(# Config

### `toy:` (the toy)

Some words.

| key | type | default | unit | range | meaning |
|---|---|---|---|---|---|
| `mode` | `fast` \| `slow` | `slow` | | | how it goes |
| `speed_mps` | real | `2.50` | m/s | > 0 | how fast |
| `retries` | integer | `3` | | [0, 10] | how often |
| `loud` | bool | `false` | | | whether it logs |
| `timeout_s` | real | `0` | s | 0 or [2, 60]; longer is silly | give up after |

### `next:`
)";

}  // namespace

TEST(ConfigFields, OneListLoadsChecksAndDescribes) {
  const ToyConfig c =
      load_toy("toy: {mode: fast, speed_mps: 4, retries: 0, loud: true, timeout_s: 5}\n");
  EXPECT_EQ(c.mode, Mode::kFast);
  EXPECT_EQ(c.speed_mps, 4);
  EXPECT_EQ(c.retries, 0);
  EXPECT_TRUE(c.loud);
  EXPECT_EQ(c.timeout_s, 5);
  // Absent keys keep the struct's defaults: the one place they are written.
  EXPECT_EQ(load_toy("toy: {}\n").speed_mps, 2.5);

  const auto rows = field_rows<ToyConfig>();
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0].type, "fast | slow");
  EXPECT_EQ(rows[0].default_text, "slow");
  EXPECT_EQ(rows[1].default_text, "2.5");
  EXPECT_EQ(rows[1].bounds, "> 0");
  EXPECT_EQ(rows[2].type, "integer");
  EXPECT_EQ(rows[2].bounds, "[0, 10]");
  EXPECT_EQ(rows[3].default_text, "false");
  EXPECT_EQ(rows[4].bounds, "0 or [2, 60]");
}

TEST(ConfigFields, ABadValueNamesFileLineFieldAndBound) {
  EXPECT_EQ(error_of("toy:\n  speed_mps: -1\n"), "toy.yaml:2: toy.speed_mps = -1: must be > 0");
  EXPECT_EQ(error_of("toy:\n  retries: 11\n"), "toy.yaml:2: toy.retries = 11: must be in [0, 10]");
  EXPECT_EQ(error_of("toy:\n  timeout_s: 1\n"),
            "toy.yaml:2: toy.timeout_s = 1: must be in [2, 60]");
  EXPECT_EQ(error_of("toy:\n  timeout_s: 0\n"), "");
  EXPECT_NE(error_of("toy:\n  mode: medium\n").find("toy.mode = medium: must be one of fast|slow"),
            std::string::npos);
  EXPECT_NE(error_of("toy:\n  sped_mps: 1\n").find("sped_mps"), std::string::npos) << "unknown key";
}

TEST(ConfigFields, TheReferenceAgreesWithTheList) {
  EXPECT_EQ(reference_mismatches(kDoc, "### `toy:`", field_rows<ToyConfig>()),
            std::vector<std::string>{});
}

TEST(ConfigFields, TheReferenceDriftingFromTheListIsCaught) {
  auto drift = [](const std::string& from, const std::string& to) {
    std::string doc = kDoc;
    doc.replace(doc.find(from), from.size(), to);
    return reference_mismatches(doc, "### `toy:`", field_rows<ToyConfig>());
  };
  auto one = [](const std::vector<std::string>& m, const std::string& says) {
    return m.size() == 1 && m[0].find(says) != std::string::npos;
  };
  EXPECT_TRUE(one(drift("`2.50`", "`3`"), "speed_mps: the doc's default is '3', the code's '2.5'"));
  EXPECT_TRUE(one(drift("| m/s | > 0 |", "| km/h | > 0 |"), "speed_mps: the doc's unit is 'km/h'"));
  EXPECT_TRUE(one(drift("[0, 10]", "[1, 10]"), "retries: the doc's range '[1, 10]'"));
  EXPECT_TRUE(one(drift("\\| `slow` |", "|"), "the doc does not name the choice 'slow'"));
  const auto renamed = drift("| `loud` |", "| `noisy` |");
  ASSERT_EQ(renamed.size(), 2u);
  EXPECT_NE(renamed[0].find("no row for loud"), std::string::npos);
  EXPECT_NE(renamed[1].find("the doc has a row for noisy, which the code does not list"),
            std::string::npos);
  EXPECT_TRUE(one(reference_mismatches(kDoc, "### `tiy:`", field_rows<ToyConfig>()), "no heading"));
}
