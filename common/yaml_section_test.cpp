#include "common/yaml_section.hpp"

#include <gtest/gtest.h>

using namespace ddswarm;

namespace {
struct Demo {
  double radius_m = 1;
  int count = 3;
  void validate() const { check_positive("demo.radius_m", radius_m); }
};
void load(YamlSection s, Demo& d) {
  s.get("radius_m", d.radius_m);
  s.get("count", d.count);
  s.finish();
}
std::string error_of(const std::string& text) {
  try {
    auto doc = YamlDocument::parse(text, "x.yaml");
    Demo d;
    doc.guard([&] {
      load(doc.section("demo"), d);
      d.validate();
    });
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(YamlSection, ReadsValuesAndKeepsDefaults) {
  auto doc = YamlDocument::parse("demo:\n  radius_m: 2.5\n", "x.yaml");
  Demo d;
  load(doc.section("demo"), d);
  EXPECT_EQ(d.radius_m, 2.5);
  EXPECT_EQ(d.count, 3);
}

TEST(YamlSection, UnknownKeyNamesFileLineAndKey) {
  EXPECT_EQ(error_of("demo:\n  radius_m: 2\n  colour: red\n"),
            "x.yaml:3: demo.colour: unknown key");
}

TEST(YamlSection, WrongTypeNamesValue) {
  EXPECT_EQ(error_of("demo:\n  count: lots\n"), "x.yaml:2: demo.count = lots: must be an integer");
  EXPECT_EQ(error_of("demo:\n  radius_m: .nan\n"),
            "x.yaml:2: demo.radius_m = .nan: must be a finite number");
}

TEST(YamlSection, ValidationErrorGetsTheLineOfTheField) {
  EXPECT_EQ(error_of("\ndemo:\n  radius_m: -4\n"), "x.yaml:3: demo.radius_m = -4: must be > 0");
}

TEST(YamlSection, SyntaxErrorAndMissingFile) {
  EXPECT_NE(error_of("demo: [1, 2\n").find("x.yaml:"), std::string::npos);
  EXPECT_THROW(YamlDocument::load_file("/nonexistent/file.yaml"), ConfigError);
}

// Found by fuzz_config: a quoted key holding a newline made a two-line error.
TEST(YamlSection, ErrorsStayOnOneLineWhateverTheFileHolds) {
  EXPECT_EQ(error_of("demo:\n  \"rad\\nius\\t\\x01\": 2\n"),
            "x.yaml:2: demo.rad\\nius\\t\\x01: unknown key");
}

TEST(YamlSection, DuplicateKeyIsAnError) {
  EXPECT_EQ(error_of("demo:\n  radius_m: 2\n  radius_m: 3\n"),
            "x.yaml:3: demo.radius_m: duplicate key (first at line 2)");
}
