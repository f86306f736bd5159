#include "launcher/preflight.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace ddswarm::gs {
namespace {

ChildSpec sh(const std::string& name, const std::string& script) {
  return {name, {"/bin/sh", "-c", script}};
}

TEST(CheckErrorLine, IsTheReadersErrorLineOrHowItEnded) {
  ChildExit e;
  e.name = "agent 0";
  e.pid = 12;
  e.exit_code = 2;
  EXPECT_EQ(
      check_error_line(e, "loading\nddswarm-agent: error: s.yaml:5: agent.x = -1: must be > 0\n"),
      "ddswarm-agent: error: s.yaml:5: agent.x = -1: must be > 0");
  EXPECT_EQ(check_error_line(e, "no\nerror line\n"),
            "agent 0 (pid 12) exited with code 2: no\\nerror line");
  e.exit_code = -1;
  e.signal = 11;
  EXPECT_EQ(check_error_line(e, ""), "agent 0 (pid 12) was killed by SIGSEGV");
}

TEST(FirstCheckError, IsTheFirstFailureInTheOrderGivenWhateverEndsFirst) {
  EXPECT_EQ(first_check_error({sh("a", "exit 0"), sh("b", "true")}), "");
  // The second fails at once, the first later: the first is the one named.
  EXPECT_EQ(first_check_error({sh("ok", "exit 0"),
                               sh("slow", "sleep 0.3; echo 'ddswarm-sim: error: slow one'; exit 2"),
                               sh("fast", "echo 'ddswarm-agent: error: fast one'; exit 2")}),
            "ddswarm-sim: error: slow one");
  EXPECT_THROW(first_check_error({{"none", {"/nonexistent/ddswarm-sim", "--check"}}}),
               std::runtime_error);
}

}  // namespace
}  // namespace ddswarm::gs
