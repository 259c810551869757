// storey-sim: the world simulator's command line (DESIGN §7).
//   storey-sim --scene NAME|FILE --describe          ground truth as JSON
//   storey-sim --scene NAME|FILE --export-obj FILE   the world mesh as OBJ
//   storey-sim --scene NAME|FILE --render DIR        top-down PNG per floor + side view
//   storey-sim --scene NAME|FILE --config FILE      hardware-in-the-loop: real LiDAR packets and
//              [--rate X] [--seed N] [--duration S]  the Go2 link over UDP/DDS (hil_runner.hpp)
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "config/parameters.hpp"
#include "tools/sim/ground_truth.hpp"
#include "tools/sim/hil_runner.hpp"
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
               "       storey-sim --scene NAME|FILE --config FILE [--rate X] [--seed N] "
               "[--duration S]\n"
               "                  [--start X,Y,Z,YAW_DEG]\n"
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
               "  --config FILE      hardware-in-the-loop: run the world in real time, send the\n"
               "                     sensor's real UDP packets (sensor.*) and serve the Go2 link\n"
               "                     (link.*) as the robot would; stop with Ctrl-C\n"
               "  --rate X           simulated seconds per wall second (default 1)\n"
               "  --seed N           noise seed (default 1)\n"
               "  --duration S       stop after S simulated seconds (default: run until stopped)\n"
               "  --help             this text\n"
               "Exit status: 0 ok, 2 bad input.\n");
}

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) {
  g_stop.store(true);
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

void print_progress(const sim::HilStats& s) {
  std::fprintf(stderr,
               "storey-sim: t %.1f s (wall %.1f s) | lidar %llu packets, %llu returns | imu %llu | "
               "commands %llu vel, %llu mode | send errors %llu | late steps %llu\n",
               s.sim_time_s, s.wall_time_s, (unsigned long long)s.lidar_packets,
               (unsigned long long)s.lidar_returns, (unsigned long long)s.imu_packets,
               (unsigned long long)s.velocity_commands, (unsigned long long)s.mode_commands,
               (unsigned long long)s.send_errors, (unsigned long long)s.late_steps);
}

int run_hil(const sim::Scene& scene, const std::string& config_path, const sim::HilOptions& o) {
  const storey::config::Result cfg = storey::config::load(config_path);
  if (!cfg.ok()) {
    for (const auto& e : cfg.errors)
      std::fprintf(stderr, "storey-sim: %s\n", e.to_string().c_str());
    std::exit(2);
  }
  sim::HilRunner runner(scene, cfg.params, o);
  for (const auto& w : runner.warnings())
    std::fprintf(stderr, "storey-sim: warning: %s\n", w.c_str());
  std::fprintf(stderr, "storey-sim: %s: %s\n", scene.name.c_str(), runner.describe().c_str());
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  runner.run(g_stop, print_progress);
  const sim::HilStats& s = runner.stats();
  const auto& r = runner.robot_state();
  std::fprintf(stderr, "storey-sim: stopped (%s)\n", g_stop.load() ? "signal" : "duration");
  std::printf(
      "{\"sim_time_s\": %.3f, \"wall_time_s\": %.3f, \"sensor\": \"%s\", \"lidar_packets\": %llu, "
      "\"lidar_returns\": %llu, \"imu_packets\": %llu, \"send_errors\": %llu, "
      "\"velocity_commands\": %llu, \"mode_commands\": %llu, \"link_dropped\": %llu, "
      "\"command_timeouts\": %llu, \"late_steps\": %llu, \"max_lag_ms\": %.2f, "
      "\"collisions\": %u, \"falls\": %u, \"stuck_events\": %u, \"distance_m\": %.3f, "
      "\"final_pose\": [%.3f, %.3f, %.3f, %.2f]}\n",
      s.sim_time_s, s.wall_time_s,
      std::string(storey::config::to_string(cfg.params.sensor.type)).c_str(),
      (unsigned long long)s.lidar_packets, (unsigned long long)s.lidar_returns,
      (unsigned long long)s.imu_packets, (unsigned long long)s.send_errors,
      (unsigned long long)s.velocity_commands, (unsigned long long)s.mode_commands,
      (unsigned long long)s.link_dropped, (unsigned long long)s.command_timeouts,
      (unsigned long long)s.late_steps, s.max_lag_s * 1e3, s.collisions, s.falls, s.stuck_events,
      s.distance_m, r.position.x(), r.position.y(), r.position.z(), r.yaw * 180.0 / M_PI);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_arg, obj_out, render_dir, start_arg, config_path;
  bool describe = false;
  sim::HilOptions hil;
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
      config_path = value();
    } else if (a == "--rate") {
      hil.rate = parse_number(value(), "--rate");
      if (!(hil.rate > 0)) bad("--rate must be > 0");
    } else if (a == "--seed") {
      const double v = parse_number(value(), "--seed");
      if (!(v >= 0) || v != std::floor(v)) bad("--seed must be a non-negative integer");
      hil.seed = uint64_t(v);
    } else if (a == "--duration") {
      hil.duration = parse_number(value(), "--duration");
      if (!(hil.duration > 0)) bad("--duration must be > 0");
    } else {
      bad("unknown argument '" + a + "' (see --help)");
    }
  }
  if (scene_arg.empty()) bad("--scene is required (see --help)");
  if (!describe && obj_out.empty() && render_dir.empty() && config_path.empty())
    bad("nothing to do: give --config, --describe, --export-obj or --render (see --help)");
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
    if (!config_path.empty()) {
      if (scene.start) hil.start = scene.start;
      return run_hil(scene, config_path, hil);
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
