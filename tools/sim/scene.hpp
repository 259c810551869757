// A simulated world: a triangle mesh plus the robot's start pose. Built from a built-in scene
// name, a YAML building description (tools/sim/scenes/*.yaml, schema in tools/sim/README.md), or
// any mesh file assimp reads.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "tools/sim/mesh.hpp"
#include "tools/sim/mesh_io.hpp"

namespace storey::tools::sim {

// Robot start: ground point under the body centre [m] and heading [rad].
struct StartPose {
  double x = 0.0, y = 0.0, z = 0.0, yaw = 0.0;
};

struct Scene {
  std::string name;
  Mesh mesh;
  std::optional<StartPose> start;     // absent for a bare mesh file: ground truth picks one
  std::vector<double> design_floors;  // floor elevations from the description (info only)
};

struct BuiltinScene {
  const char* name;
  const char* yaml;
};
// Every scenes/*.yaml, embedded at build time (sorted by name).
const std::vector<BuiltinScene>& builtin_scenes();

// Builds the mesh of a YAML building description. `source` names the text in errors
// ("office.yaml"). Throws std::runtime_error "source:line:col: key: reason" on bad input.
Scene build_scene_from_yaml(const std::string& text, const std::string& source);

// NAME of a built-in scene, a .yaml/.yml description, or a mesh file (OBJ, STL, PLY, DAE...).
// Throws std::runtime_error with a one-line reason.
Scene load_scene(const std::string& name_or_file, const MeshLoadOptions& mesh_options = {});

}  // namespace storey::tools::sim
