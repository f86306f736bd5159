#include "launcher/preflight.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <sstream>
#include <thread>

#include "common/config_error.hpp"

namespace ddswarm::gs {

std::string check_error_line(const ChildExit& e, const std::string& output) {
  std::string line;
  std::istringstream lines(output);
  for (std::string l; std::getline(lines, l);)
    if (l.find(": error: ") != std::string::npos) line = l;
  if (!line.empty()) return line;
  std::string said = output;
  while (!said.empty() && (said.back() == '\n' || said.back() == ' ')) said.pop_back();
  return one_line(e.describe() + (said.empty() ? "" : ": " + said));
}

std::string first_check_error(const std::vector<ChildSpec>& checks) {
  struct Result {
    ChildExit exit;
    std::string output;
    std::exception_ptr failed;
  };
  std::vector<Result> results(checks.size());
  // As many at once as there are cores: a check is CPU-bound start-up (the
  // program's libraries, its reading of the file).
  const std::size_t workers =
      std::min<std::size_t>(checks.size(), std::max(2u, std::thread::hardware_concurrency()));
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> threads;
  for (std::size_t w = 0; w < workers; ++w)
    threads.emplace_back([&] {
      for (std::size_t i = next++; i < checks.size(); i = next++) {
        try {
          results[i].exit = run_to_end(checks[i], results[i].output);
        } catch (...) {
          results[i].failed = std::current_exception();
        }
      }
    });
  for (auto& t : threads) t.join();
  for (auto& r : results) {
    if (r.failed) std::rethrow_exception(r.failed);
    if (r.exit.exit_code != 0) return check_error_line(r.exit, r.output);
  }
  return "";
}

}  // namespace ddswarm::gs
