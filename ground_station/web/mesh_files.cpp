#include "ground_station/web/mesh_files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>

#include "common/mesh_loader.hpp"

namespace ddswarm::gs::web {

std::vector<MeshUrl> MeshFiles::offer(const msg::Scene& s) {
  namespace fs = std::filesystem;
  std::vector<MeshUrl> out;
  std::lock_guard<std::mutex> lock(mu_);
  for (const auto& m : s.meshes()) {
    MeshUrl u;
    const fs::path name = m.file().to_string();
    std::string ext = name.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::error_code ec;
    const fs::path file = name.is_absolute() ? name : base_ / name;
    if (name.empty() || !mesh_format_supported(name)) {
      u.why = "not a mesh file";
    } else if (!fs::is_regular_file(file, ec)) {
      u.why = "no such file here";
    } else {
      const auto size = fs::file_size(file, ec);
      const auto mtime = fs::last_write_time(file, ec);
      auto it = hashes_.find(file);
      if (it == hashes_.end() || it->second.size != size || it->second.mtime != mtime) {
        try {
          it = hashes_.insert_or_assign(file, Known{size, mtime, file_hash(file)}).first;
        } catch (const MeshError&) {
          it = hashes_.end();
        }
      }
      if (it == hashes_.end()) {
        u.why = "cannot be read here";
      } else if (it->second.hash != m.content_hash()) {
        u.why = "differs from the server's";
      } else {
        u.url = fmt::format("/mesh/{:016x}{}", m.content_hash(), ext);
        served_[u.url] = file;
      }
    }
    out.push_back(std::move(u));
  }
  return out;
}

std::optional<std::filesystem::path> MeshFiles::find(std::string_view path) const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = served_.find(std::string(path));
  if (it == served_.end()) return std::nullopt;
  return it->second;
}

}  // namespace ddswarm::gs::web
