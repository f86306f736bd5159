// ddswarm-sim's command line: its options override the scenario, and a value
// the server would refuse is named with the file it came with.
#include "sim_server/sim_cli.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/config_error.hpp"

using namespace ddswarm;
using namespace ddswarm::sim;

namespace {
const std::string kThesis = std::string(DDSWARM_CONFIG_DIR) + "/thesis_course.yaml";

// The configuration `ddswarm-sim args...` would serve.
ServerConfig config_of(std::vector<std::string> args) {
  CLI::App app;
  SimCommandLine cli;
  cli.add_to(app);
  args.insert(args.begin(), "ddswarm-sim");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  app.parse(static_cast<int>(argv.size()), argv.data());
  return cli.config_for(app);
}
}  // namespace

TEST(SimCommandLine, TheScenarioAsWrittenWithoutOptions) {
  const auto cfg = config_of({kThesis});
  EXPECT_EQ(cfg.scenario.drones, 6);
  EXPECT_EQ(cfg.scenario.mode, TimeMode::kRealtime);
  EXPECT_EQ(cfg.dds.security_role, "server");  // only used under --secure
}

TEST(SimCommandLine, OptionsOverrideTheScenario) {
  const auto cfg = config_of({"--scenario", kThesis, "--drones", "12", "--mode", "lockstep",
                              "--seed", "42", "--domain", "7"});
  EXPECT_EQ(cfg.scenario.drones, 12);
  EXPECT_EQ(cfg.scenario.mode, TimeMode::kLockstep);
  EXPECT_EQ(cfg.scenario.seed, 42u);
  EXPECT_EQ(cfg.dds.domain_id, 7);
}

TEST(SimCommandLine, ARefusedOverrideNamesTheFileAndTheField) {
  try {
    config_of({kThesis, "--drones", "5000"});
    FAIL() << "5000 drones were accepted";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(kThesis), std::string::npos) << m;
    EXPECT_NE(m.find("scenario.drones = 5000"), std::string::npos) << m;
    EXPECT_NE(m.find("command line"), std::string::npos) << m;
  }
}
