#include "agent/law_plugin.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <map>
#include <mutex>

namespace ddswarm::agent {

law::MakeLaw plugin_factory(const std::string& path, const std::string& field) {
  static std::mutex mu;
  static std::map<std::string, law::MakeLaw> loaded;
  const std::lock_guard<std::mutex> lock(mu);
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(path, ec);
  const std::string key = ec ? path : abs.lexically_normal().string();
  if (auto it = loaded.find(key); it != loaded.end()) return it->second;
  if (path.empty())
    throw law::ParamError(field, "\"\"", "a plug-in law needs the path of its library");
  if (!std::filesystem::is_regular_file(key, ec))
    throw law::ParamError(field, path, "no such file");
  // RTLD_LOCAL: two plug-ins may use the same names for their own things.
  void* lib = dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!lib) {
    const char* why = dlerror();
    throw law::ParamError(field, path,
                          std::string("cannot be loaded: ") + (why ? why : "unknown error"));
  }
  auto* version = reinterpret_cast<int (*)()>(dlsym(lib, "ddswarm_law_api_version"));
  auto* factory = reinterpret_cast<law::MakeLaw (*)()>(dlsym(lib, "ddswarm_law_factory"));
  if (!version || !factory) {
    dlclose(lib);
    throw law::ParamError(
        field, path,
        "is not a ddswarm law plug-in: it exports no ddswarm_law_api_version or "
        "ddswarm_law_factory (export the law with DDSWARM_LAW_PLUGIN, docs/laws.md)");
  }
  if (const int v = version(); v != law::kApiVersion) {
    dlclose(lib);
    throw law::ParamError(field, path,
                          "was built against law API version " + std::to_string(v) +
                              ", this ddswarm has version " + std::to_string(law::kApiVersion) +
                              ": rebuild it against this ddswarm's ddswarm/law.hpp");
  }
  const law::MakeLaw make = factory();
  if (!make) {
    dlclose(lib);
    throw law::ParamError(field, path, "its ddswarm_law_factory returned no factory");
  }
  loaded[key] = make;
  return make;
}

}  // namespace ddswarm::agent
