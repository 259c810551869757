// Mesh files: load OBJ, STL, PLY, DAE (anything assimp reads) and export OBJ.
#pragma once

#include <string>

#include "tools/sim/mesh.hpp"

namespace storey::tools::sim {

enum class UpAxis { z, y };

struct MeshLoadOptions {
  double scale = 1.0;     // file units -> metres (0.001 for millimetre CAD exports)
  UpAxis up = UpAxis::z;  // y-up files (most DAE/OBJ from modelling tools) are rotated to z-up
};

// Loads every mesh of every node of the file, with node transforms applied, into one Mesh.
// Throws std::runtime_error naming the file and the reason on failure.
Mesh load_mesh(const std::string& path, const MeshLoadOptions& options = {});

// Writes a Wavefront OBJ (v/f lines, 1-based indices). Throws std::runtime_error on I/O failure.
void export_obj(const Mesh& mesh, const std::string& path);

}  // namespace storey::tools::sim
