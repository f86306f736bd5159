#pragma once
// Tests only: a scratch directory that stands in for /dev/shm, removed with
// everything in it when the test ends.
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace ddswarm::test_util {

struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/ddswarm-shm-test.XXXXXX";
    path = mkdtemp(tmpl);
  }
  ~TempDir() { std::system(("rm -rf " + path).c_str()); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Writes a file of `bytes` bytes; returns its path.
  std::string touch(const std::string& name, std::size_t bytes = 4096) const {
    std::string p = path + "/" + name;
    std::ofstream(p) << std::string(bytes, 'x');
    return p;
  }
  bool has(const std::string& name) const { return access((path + "/" + name).c_str(), F_OK) == 0; }
};

}  // namespace ddswarm::test_util
