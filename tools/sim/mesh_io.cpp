#include "tools/sim/mesh_io.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace storey::tools::sim {
namespace {

void collect(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, Mesh& out) {
  const aiMatrix4x4 m = parent * node->mTransformation;
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    const aiMesh* am = scene->mMeshes[node->mMeshes[i]];
    const auto base = static_cast<uint32_t>(out.vertices.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D p = m * am->mVertices[v];
      out.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      out.triangles.push_back(
          {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], m, out);
}

}  // namespace

Mesh load_mesh(const std::string& path, const MeshLoadOptions& options) {
  if (!(options.scale > 0.0) || !std::isfinite(options.scale))
    throw std::runtime_error(path + ": mesh scale must be a positive number");
  Assimp::Importer importer;
  // Drop normals/colours/UVs: only geometry matters; pre-transform is done by hand (collect).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_COLORS |
                                                          aiComponent_TEXCOORDS |
                                                          aiComponent_MATERIALS);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_RemoveComponent | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw std::runtime_error(path + ": cannot load mesh: " + importer.GetErrorString());
  Mesh mesh;
  collect(scene, scene->mRootNode, aiMatrix4x4(), mesh);
  const auto s = static_cast<float>(options.scale);
  for (auto& v : mesh.vertices) {
    if (options.up == UpAxis::y) v = Eigen::Vector3f(v.x(), -v.z(), v.y());  // y-up -> z-up
    v *= s;
  }
  if (mesh.empty()) throw std::runtime_error(path + ": mesh has no triangles");
  if (!mesh.valid()) throw std::runtime_error(path + ": mesh has non-finite vertices");
  return mesh;
}

void export_obj(const Mesh& mesh, const std::string& path) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "w"), &std::fclose);
  if (!f) throw std::runtime_error(path + ": cannot open for writing");
  std::fprintf(f.get(), "# storey-sim mesh: %zu vertices, %zu triangles, metres, z up\n",
               mesh.vertices.size(), mesh.triangles.size());
  for (const auto& v : mesh.vertices)
    std::fprintf(f.get(), "v %.6g %.6g %.6g\n", v.x(), v.y(), v.z());
  for (const auto& t : mesh.triangles)
    std::fprintf(f.get(), "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
  if (std::ferror(f.get())) throw std::runtime_error(path + ": write error");
}

}  // namespace storey::tools::sim
