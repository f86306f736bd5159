// libFuzzer: scenario YAML text -> the three processes' config loaders
// (load_server_config, load_agent_config, load_gs_config), exactly as the
// binaries call them. Any input must either load and validate, or be refused
// with a ConfigError (one line naming file, line and field). Any other
// exception, a crash or undefined behaviour is a bug.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "agent/agent_app_config.hpp"
#include "common/config_error.hpp"
#include "ground_station/gs_file_config.hpp"
#include "sim_server/sim_server.hpp"

namespace {

std::string scratch_path() {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/ddswarm_fuzz_config_" + std::to_string(::getpid()) +
         ".yaml";
}

void expect_one_line(const ddswarm::ConfigError& e) {
  const std::string what = e.what();
  // The message is what users see: one line, never empty.
  if (what.empty() || what.find('\n') != std::string::npos) {
    std::fprintf(stderr, "ConfigError is not one line: [%s]\n", what.c_str());
    __builtin_trap();
  }
}

template <class F>
void load_or_refuse(F&& load) {
  try {
    load();
  } catch (const ddswarm::ConfigError& e) {
    expect_one_line(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = scratch_path();
  if (size > 64 * 1024) return -1;  // configs are small; bigger only slows the search
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  load_or_refuse([&] { (void)ddswarm::sim::load_server_config(path); });
  load_or_refuse([&] { (void)ddswarm::agent::load_agent_config(path); });
  load_or_refuse([&] { (void)ddswarm::gs::load_gs_config(path); });
  return 0;
}
