#pragma once
// The mesh files a Scene names, served to the page (docs/worlds.md, "Mesh
// obstacles"). The Scene carries each mesh's file name and the hash of its
// bytes, never the triangles; the bridge finds the file on this machine
// (relative to its scenario file's folder, or absolute) and serves it at
// /mesh/<hash><ext> only when its bytes hash to the Scene's, so the page draws
// what the server simulates, and a Scene sample cannot make the bridge
// serve a file of its choosing. A mesh without its file is drawn as its bounds.
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "Scene.h"

namespace ddswarm::gs::web {

/// Where one of a Scene's meshes can be fetched, or why it cannot.
struct MeshUrl {
  std::string url;  ///< "/mesh/<16 hex digits><ext>", empty when not served
  std::string why;  ///< when not served: "no such file here", "differs from the server's", ...
};

class MeshFiles {
 public:
  /// base_dir: what relative file names are relative to (the folder of the
  /// ground station's --config), as they are to the server's scenario file.
  explicit MeshFiles(std::filesystem::path base_dir) : base_(std::move(base_dir)) {}

  /// Where each of s's meshes is served (in s's order); registers each file found.
  /// Thread-safe.
  std::vector<MeshUrl> offer(const msg::Scene& s);
  /// The file behind a request path "/mesh/…" that offer() gave out; nullopt
  /// otherwise. Thread-safe.
  std::optional<std::filesystem::path> find(std::string_view path) const;

 private:
  struct Known {
    std::uintmax_t size;
    std::filesystem::file_time_type mtime;
    std::uint64_t hash;
  };
  std::filesystem::path base_;
  mutable std::mutex mu_;
  std::map<std::string, std::filesystem::path> served_;  ///< url -> file
  std::map<std::filesystem::path, Known> hashes_;        ///< files hashed, while unchanged
};

}  // namespace ddswarm::gs::web
