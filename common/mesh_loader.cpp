#include "common/mesh_loader.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <fstream>
#include <limits>
#include <system_error>

#include "common/config_error.hpp"

namespace ddswarm {

bool mesh_format_supported(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".obj" || ext == ".stl" || ext == ".gltf" || ext == ".glb";
}

TriangleMesh read_mesh_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw MeshError("no such file");
  if (!std::filesystem::is_regular_file(file, ec)) throw MeshError("not a regular file");
  if (!mesh_format_supported(file))
    throw MeshError("unsupported format '" + file.extension().string() +
                    "' (ddswarm reads .obj, .stl, .gltf and .glb)");
  if (std::filesystem::file_size(file, ec) == 0) throw MeshError("the file is empty");
  Assimp::Importer importer;
  // Points and lines are no obstacle: drop them rather than keep degenerate faces.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                           aiProcess_SortByPType | aiProcess_JoinIdenticalVertices);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mNumMeshes == 0) {
    const std::string why = importer.GetErrorString();
    // A file of points or lines only leaves assimp no mesh to output.
    if (why.find("No output meshes") != std::string::npos) throw MeshError("has no triangles");
    if (!scene || !why.empty())
      throw MeshError(why.empty() ? "cannot be read as a mesh" : "cannot be read: " + why);
    throw MeshError("has no triangles");
  }
  TriangleMesh out;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const Eigen::Vector3f q(p.x, p.y, p.z);
      if (!q.allFinite()) throw MeshError("has a non-finite vertex");
      out.vertices.push_back(q);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      out.triangles.push_back(
          {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
      if (out.triangles.size() > kMaxMeshTriangles)
        throw MeshError("has more than " + std::to_string(kMaxMeshTriangles) + " triangles");
    }
  }
  if (out.triangles.empty()) throw MeshError("has no triangles");
  return out;
}

std::uint64_t file_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw MeshError("cannot be read");
  std::uint64_t h = 0xcbf29ce484222325ULL;
  char buf[1 << 16];
  while (in) {
    in.read(buf, sizeof buf);
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 0x100000001b3ULL;
    }
  }
  return h;
}

void load_meshes(SceneConfig& scene, const std::filesystem::path& base_dir) {
  for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
    MeshObstacle& m = scene.meshes[i];
    const std::string field = "scene.meshes[" + std::to_string(i) + "].file";
    const std::filesystem::path path = std::filesystem::path(m.file).is_absolute()
                                           ? std::filesystem::path(m.file)
                                           : base_dir / m.file;
    TriangleMesh mesh;
    try {
      mesh = read_mesh_file(path);
      m.content_hash = file_hash(path);
    } catch (const MeshError& e) {
      throw FieldError(field, path.string(), e.what());
    }
    check_positive("scene.meshes[" + std::to_string(i) + "].scale", m.scale);
    const Eigen::Matrix3d r = m.rotation() * m.scale;
    for (auto& v : mesh.vertices) v = (r * v.cast<double>() + m.position).cast<float>();
    // The bounds are those of the corners triangles use (a file may hold stray vertices).
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const auto& t : mesh.triangles)
      for (std::uint32_t k : t) {
        lo = lo.cwiseMin(mesh.vertices[k].cast<double>());
        hi = hi.cwiseMax(mesh.vertices[k].cast<double>());
      }
    m.triangle_count = static_cast<std::uint32_t>(mesh.triangles.size());
    m.bounds_min = lo;
    m.bounds_max = hi;
    m.world = std::make_shared<const TriangleMesh>(std::move(mesh));
  }
}

}  // namespace ddswarm
