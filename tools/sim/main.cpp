// storey-sim: the world simulator's command line (DESIGN §7).
//   storey-sim --scene NAME|FILE --describe          ground truth as JSON
//   storey-sim --scene NAME|FILE --export-obj FILE   the world mesh as OBJ
//   storey-sim --scene NAME|FILE --render DIR        top-down PNG per floor + side view
// Hardware-in-the-loop packet emission (--config) comes with the LiDAR encoders and the Go2 robot
// stand-in (issue #5 item 6, second half).
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "tools/sim/ground_truth.hpp"
#include "tools/sim/mesh_io.hpp"
#include "tools/sim/render.hpp"
#include "tools/sim/scene.hpp"

namespace sim = storey::tools::sim;

namespace {

void usage(FILE* out) {
  std::fprintf(out,
               "usage: storey-sim --scene NAME|FILE [--describe] [--export-obj FILE] "
               "[--render DIR]\n"
               "                  [--scale S] [--up z|y] [--start X,Y,Z,YAW_DEG]\n"
               "  --scene NAME|FILE  built-in scene (");
  const auto& b = sim::builtin_scenes();
  for (std::size_t i = 0; i < b.size(); ++i) std::fprintf(out, "%s%s", i ? ", " : "", b[i].name);
  std::fprintf(out,
               "),\n"
               "                     a YAML building description, or a mesh file (OBJ, STL, PLY, "
               "DAE)\n"
               "  --describe         print the ground truth as JSON: bounding box, floors (z_m,\n"
               "                     traversable_area_m2), traversable_volume_m3, "
               "occupied_volume_m3\n"
               "  --export-obj FILE  write the world mesh as Wavefront OBJ\n"
               "  --render DIR       write DIR/floor_<i>.png (top-down) and DIR/side.png\n"
               "  --scale S          mesh file units to metres (default 1)\n"
               "  --up z|y           mesh file up axis (default z)\n"
               "  --start X,Y,Z,YAW  robot start (ground point [m], yaw [deg]); default: the "
               "scene's\n"
               "  --help             this text\n"
               "Exit status: 0 ok, 2 bad input.\n");
}

[[noreturn]] void bad(const std::string& why) {
  std::fprintf(stderr, "storey-sim: %s\n", why.c_str());
  std::exit(2);
}

double parse_number(const std::string& s, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v))
    bad(std::string(what) + ": not a number: '" + s + "'");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_arg, obj_out, render_dir, start_arg;
  bool describe = false;
  sim::MeshLoadOptions mesh_opt;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= args.size()) bad(a + " needs a value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    } else if (a == "--scene") {
      scene_arg = value();
    } else if (a == "--describe") {
      describe = true;
    } else if (a == "--export-obj") {
      obj_out = value();
    } else if (a == "--render") {
      render_dir = value();
    } else if (a == "--scale") {
      mesh_opt.scale = parse_number(value(), "--scale");
      if (!(mesh_opt.scale > 0)) bad("--scale must be > 0");
    } else if (a == "--up") {
      const std::string u = value();
      if (u != "z" && u != "y") bad("--up must be z or y, got '" + u + "'");
      mesh_opt.up = u == "y" ? sim::UpAxis::y : sim::UpAxis::z;
    } else if (a == "--start") {
      start_arg = value();
    } else if (a == "--config") {
      bad("--config (hardware-in-the-loop packet emission) is not implemented yet");
    } else {
      bad("unknown argument '" + a + "' (see --help)");
    }
  }
  if (scene_arg.empty()) bad("--scene is required (see --help)");
  if (!describe && obj_out.empty() && render_dir.empty())
    bad("nothing to do: give --describe, --export-obj or --render (see --help)");
  try {
    sim::Scene scene = sim::load_scene(scene_arg, mesh_opt);
    if (!start_arg.empty()) {
      std::vector<double> v;
      std::size_t p = 0;
      while (p <= start_arg.size()) {
        const std::size_t q = std::min(start_arg.find(',', p), start_arg.size());
        v.push_back(parse_number(start_arg.substr(p, q - p), "--start"));
        p = q + 1;
      }
      if (v.size() != 4) bad("--start needs X,Y,Z,YAW_DEG");
      scene.start = sim::StartPose{v[0], v[1], v[2], v[3] * M_PI / 180.0};
    }
    if (!obj_out.empty()) sim::export_obj(scene.mesh, obj_out);
    if (describe || !render_dir.empty()) {
      const sim::GroundTruth gt(scene.mesh, scene.start);
      if (describe) std::fputs(gt.describe_json(scene.name).c_str(), stdout);
      if (!render_dir.empty()) {
        const auto files = sim::render_scene(gt, render_dir);
        for (const auto& f : files) std::fprintf(stderr, "storey-sim: wrote %s\n", f.c_str());
      }
    }
  } catch (const std::exception& e) {
    bad(e.what());
  }
  return 0;
}
