// `storey sim` (DESIGN §7): lockstep simulated exploration, the main job. Linked into the storey
// executable when the tools are built (firmware/CMakeLists.txt); the run itself is sim_run.cpp.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "firmware/commands.hpp"
#include "tools/sim/sim_run.hpp"

namespace storey::firmware {

namespace {

void usage(FILE* out) {
  std::fprintf(
      out,
      "usage: storey sim [--scene NAME|FILE] [--start X,Y,Z,YAW_DEG] [--sensor vlp16|mid360]\n"
      "                  [--seed N] [--method M] [--ablation NAME] [--time-limit S]\n"
      "                  [--out DIR] [--config FILE]\n\n"
      "Lockstep simulated exploration (deterministic for a seed). Progress every 5 simulated\n"
      "seconds on stderr; ends when the planner reports exploration complete or at the\n"
      "time limit, then writes the run record to DIR (default out/<scene>): metrics.json,\n"
      "map.ply, graph.json, trace.json, latency.md, tracking.csv, plan.csv, floor_<i>.png,\n"
      "side.png, report.md, diagnostics.md.\n\n"
      "  --scene NAME|FILE  built-in scene (office, maze, teaching_building, house, ...) or a\n"
      "                     .yaml building / mesh file (default office)\n"
      "  --start X,Y,Z,YAW  start pose: ground point [m] and heading [deg] (default: scene's)\n"
      "  --sensor S         vlp16 (default) or mid360\n"
      "  --seed N           seed of the sensor noise and graph sampling (default 1)\n"
      "  --method M         storey (default: the paper's method), or a baseline over the same\n"
      "                     map, graph, speed limits and trajectories: nearest-frontier,\n"
      "                     fael-like (one floor's 2D grid), tare-like (height-bounded links)\n"
      "  --ablation NAME    storey only: no-tentative, no-c-sur, no-c-exp, boundary-frontiers,\n"
      "                     no-prior, no-incremental\n"
      "  --time-limit S     simulated seconds before giving up (default 1200)\n"
      "  --out DIR          run record folder (default out/<scene>)\n"
      "  --config FILE      configuration (default config/default.yaml)\n");
}

bool parse_double(std::string_view s, double& out) {
  const std::string str(s);
  char* end = nullptr;
  out = std::strtod(str.c_str(), &end);
  return !str.empty() && end && *end == '\0' && std::isfinite(out);
}

}  // namespace

int cmd_sim(int argc, char** argv) {
  tools::sim::SimRunOptions o;
  bool out_given = false;
  auto bad = [](const std::string& msg) {
    std::fprintf(stderr, "storey sim: %s\n", msg.c_str());
    return 2;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") {
      usage(stdout);
      return 0;
    }
    if (i + 1 >= argc) return bad(std::string(a) + ": missing value (see storey sim --help)");
    const std::string v = argv[++i];
    double d = 0;
    if (a == "--scene") {
      o.scene = v;
    } else if (a == "--start") {
      double p[4];
      size_t pos = 0;
      int n = 0;
      for (; n < 4; ++n) {
        const size_t comma = v.find(',', pos);
        if (!parse_double(std::string_view(v).substr(pos, comma - pos), p[n])) break;
        if (comma == std::string::npos) {
          ++n;
          break;
        }
        pos = comma + 1;
      }
      if (n != 4) return bad("--start " + v + ": expected X,Y,Z,YAW_DEG (four numbers)");
      o.start = tools::sim::StartPose{p[0], p[1], p[2], p[3] * M_PI / 180.0};
    } else if (a == "--sensor") {
      o.sensor = v;
    } else if (a == "--seed") {
      if (!parse_double(v, d) || d < 0 || d != std::floor(d))
        return bad("--seed " + v + ": expected a non-negative integer");
      o.seed = uint64_t(d);
    } else if (a == "--method") {
      o.method = v;
    } else if (a == "--ablation") {
      o.ablation = v;
    } else if (a == "--time-limit") {
      if (!parse_double(v, d) || d <= 0) return bad("--time-limit " + v + ": expected seconds > 0");
      o.time_limit_s = d;
    } else if (a == "--out") {
      o.out_dir = v;
      out_given = true;
    } else if (a == "--config") {
      o.config = v;
    } else {
      return bad("unknown argument '" + std::string(a) + "' (see storey sim --help)");
    }
  }
  if (!out_given) {
    std::string name = o.scene;
    const size_t slash = name.find_last_of('/');
    if (slash != std::string::npos) name = name.substr(slash + 1);
    const size_t dot = name.find('.');
    if (dot != std::string::npos && dot > 0) name = name.substr(0, dot);
    o.out_dir = "out/" + name;
  }
  try {
    std::fprintf(stderr,
                 "storey sim: scene %s, method %s%s%s, sensor %s, seed %llu, time limit %.0f s\n",
                 o.scene.c_str(), o.method.c_str(), o.ablation.empty() ? "" : ", ablation ",
                 o.ablation.c_str(), o.sensor.c_str(), (unsigned long long)o.seed, o.time_limit_s);
    const tools::sim::SimRunResult r = tools::sim::run_exploration(o);
    const auto& m = r.metrics;
    std::fprintf(stderr,
                 "storey sim: %s\n  coverage %.1f %%, floors %d/%d, %.1f s, %.1f m, collisions %u, "
                 "falls %u, safety stops %u\n",
                 r.end_reason.c_str(), 100 * m.traversable_coverage, m.floors_explored,
                 m.floors_total, m.exploration_time_s, m.trajectory_length_m, m.collisions, m.falls,
                 m.safety_stops);
    std::printf("%s\n", r.report_path.c_str());
    return m.success ? 0 : 1;
  } catch (const std::invalid_argument& e) {
    return bad(e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "storey sim: %s\n", e.what());
    return 1;
  }
}

}  // namespace storey::firmware
