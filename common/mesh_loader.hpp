#pragma once
// Mesh files for static obstacles (YAML `scene.meshes`): read with assimp
// into triangles, placed in the world frame. Only the server reads them; a
// Scene sample carries each entry with its triangle count, bounds and the
// file's hash (docs/worlds.md, "Mesh obstacles").
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "common/scene.hpp"

namespace ddswarm {

/// A mesh file cannot be used; what() is the reason, e.g. "no such file".
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The most triangles one file may hold: a world, not a scanned city.
constexpr std::size_t kMaxMeshTriangles = 1'000'000;

/// True for the formats ddswarm reads: .obj, .stl, .gltf, .glb (any case).
bool mesh_format_supported(const std::filesystem::path& file);

/// The triangles of every mesh in file, in the file's own coordinates (node
/// transforms applied; faces with more than three corners triangulated;
/// points and lines dropped). Throws MeshError naming the reason: no such
/// file, not a regular file, an unsupported format, assimp's parse error,
/// no triangles, more than kMaxMeshTriangles, a non-finite vertex.
TriangleMesh read_mesh_file(const std::filesystem::path& file);

/// FNV-1a (64 bit) of a file's bytes: what the web view's server checks a
/// file against before serving it as a Scene's mesh. Throws MeshError when
/// the file cannot be read.
std::uint64_t file_hash(const std::filesystem::path& file);

/// Reads every scene.meshes entry (file relative to base_dir unless
/// absolute), places its triangles in the world (scale, rotation,
/// position) and fills triangle_count, content_hash, bounds and world.
/// Throws FieldError("scene.meshes[i].file", file, reason), so a loader's
/// guard adds the scenario file and line.
void load_meshes(SceneConfig& scene, const std::filesystem::path& base_dir);

}  // namespace ddswarm
