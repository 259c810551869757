#include "tools/eval/eval_options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace storey::tools::eval {

const std::vector<std::string>& default_scenes() {
  static const std::vector<std::string> s = {"office", "maze", "teaching_building", "house"};
  return s;
}
const std::vector<std::string>& default_methods() {
  static const std::vector<std::string> m = {"storey", "nearest-frontier", "fael-like",
                                             "tare-like"};
  return m;
}

void print_eval_usage(FILE* out) {
  std::fprintf(
      out,
      "usage: storey-eval [--scenes A,B,...] [--methods A,B,...] [--ablations A,B,...]\n"
      "                   [--preset tables|ablations|paper] [--seeds N|A,B,...] [--jobs N]\n"
      "                   [--time-limit S|SCENE=S,...] [--out DIR] [--storey PATH]\n"
      "                   [--config FILE] [--report-only]\n\n"
      "Runs `storey sim` for every scene x method x ablation x seed (in parallel, resumable)\n"
      "and writes DIR/results.md (the paper's Tables I-IV, mean +- std over seeds),\n"
      "DIR/results.csv (one row per run), DIR/results.json and DIR/coverage_<scene>.png.\n"
      "Each run's record stays in DIR/runs/<scene>/<method>[-<ablation>]/seed<N>/ with the\n"
      "child's output in log.txt. A run whose folder holds a complete metrics.json is not\n"
      "redone; failed runs (no metrics.json) are tried again next time.\n\n"
      "  --scenes LIST      built-in scenes or scene files (default office,maze,\n"
      "                     teaching_building,house)\n"
      "  --methods LIST     storey,nearest-frontier,fael-like,tare-like (default: all)\n"
      "  --ablations LIST   full (no --ablation) and/or storey sim ablations: no-tentative,\n"
      "                     no-c-sur, no-c-exp, boundary-frontiers, no-prior, no-incremental\n"
      "                     (default full)\n"
      "  --preset NAME      tables: Tables I-II (default scenes x all methods); ablations:\n"
      "                     Tables III-IV (maze, storey, full + every ablation); paper: both.\n"
      "                     Not combined with --scenes/--methods/--ablations\n"
      "  --seeds N|LIST     N: seeds 1..N (default 5); A,B,...: exactly those seeds\n"
      "  --jobs N           parallel runs (default: the machine's cores)\n"
      "  --time-limit LIST  simulated seconds per run: S sets every scene's (the teaching\n"
      "                     building's default included), SCENE=S one scene's (default\n"
      "                     1800,teaching_building=3000)\n"
      "  --out DIR          output folder (default out/eval)\n"
      "  --storey PATH      the storey executable (default: next to storey-eval)\n"
      "  --config FILE      configuration passed to every run\n"
      "  --report-only      write the results from the runs already in DIR; run nothing\n");
}

namespace {

std::vector<std::string> split_list(const std::string& v) {
  std::vector<std::string> out;
  size_t pos = 0;
  for (;;) {
    const size_t comma = v.find(',', pos);
    out.push_back(v.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return out;
}

bool parse_uint(const std::string& s, uint64_t& out) {
  if (s.empty() || s.size() > 18 || !std::all_of(s.begin(), s.end(), ::isdigit)) return false;
  out = std::strtoull(s.c_str(), nullptr, 10);
  return true;
}

// Names become folder names and child arguments: letters, digits, '_', '-', '.' only for methods
// and ablations; scenes may also be paths ('/'), but their folder name is the file stem.
bool valid_name(const std::string& s, bool allow_path) {
  if (s.empty() || s == "." || s == "..") return false;
  for (const char c : s) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ||
                    c == '.' || (allow_path && c == '/');
    if (!ok) return false;
  }
  return true;
}

}  // namespace

ParseResult parse_eval_args(const std::vector<std::string>& args) {
  ParseResult r;
  EvalOptions& o = r.options;
  MatrixGroup flags{default_scenes(), default_methods(), {"full"}};
  bool matrix_flag = false;
  std::string matrix_flag_name;
  bool seeds_given = false;
  std::vector<std::string> limit_scenes;  // scenes named in --time-limit
  auto fail = [&](const std::string& msg) {
    r.error = msg;
    return r;
  };
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      o.help = true;
      return r;
    }
    if (a == "--report-only") {
      o.report_only = true;
      continue;
    }
    const bool known = a == "--scenes" || a == "--methods" || a == "--ablations" ||
                       a == "--preset" || a == "--seeds" || a == "--jobs" || a == "--time-limit" ||
                       a == "--out" || a == "--storey" || a == "--config";
    if (!known) return fail("unknown argument '" + a + "' (see storey-eval --help)");
    if (i + 1 >= args.size()) return fail(a + ": missing value (see storey-eval --help)");
    const std::string& v = args[++i];
    if (a == "--scenes" || a == "--methods" || a == "--ablations") {
      std::vector<std::string> list = split_list(v);
      for (const auto& n : list)
        if (!valid_name(n, a == "--scenes"))
          return fail(a + " " + v + ": bad name '" + n +
                      "' (letters, digits, '_', '-', '.'; comma separated)");
      (a == "--scenes" ? flags.scenes : a == "--methods" ? flags.methods : flags.ablations) = list;
      matrix_flag = true;
      matrix_flag_name = a;
    } else if (a == "--preset") {
      for (const auto& p : split_list(v)) {
        if (p != "tables" && p != "ablations" && p != "paper")
          return fail("--preset " + v + ": unknown preset '" + p +
                      "' (known: tables, ablations, paper)");
        o.presets.push_back(p);
      }
    } else if (a == "--seeds") {
      o.seeds.clear();
      uint64_t n = 0;
      if (v.find(',') == std::string::npos) {
        if (!parse_uint(v, n) || n == 0 || n > 1000)
          return fail("--seeds " + v + ": expected a count 1..1000 or a list A,B,...");
        for (uint64_t s = 1; s <= n; ++s) o.seeds.push_back(s);
      } else {
        for (const auto& p : split_list(v)) {
          if (!parse_uint(p, n)) return fail("--seeds " + v + ": '" + p + "' is not a seed");
          if (std::find(o.seeds.begin(), o.seeds.end(), n) == o.seeds.end()) o.seeds.push_back(n);
        }
      }
      seeds_given = true;
    } else if (a == "--jobs") {
      uint64_t n = 0;
      if (!parse_uint(v, n) || n == 0 || n > 1024)
        return fail("--jobs " + v + ": expected an integer 1..1024");
      o.jobs = int(n);
    } else if (a == "--time-limit") {
      // Numbers first (they replace every scene's limit), then SCENE=S entries on top.
      std::vector<std::pair<std::string, double>> scenes;
      bool all_given = false;
      for (const auto& item : split_list(v)) {
        const size_t eq = item.find('=');
        const std::string name = eq == std::string::npos ? "" : item.substr(0, eq);
        const std::string num = eq == std::string::npos ? item : item.substr(eq + 1);
        double d = 0;
        if (!parse_seconds(num, d))
          return fail("--time-limit " + v + ": '" + item +
                      "': expected simulated seconds > 0 or SCENE=seconds");
        if (eq == std::string::npos) {
          if (all_given) return fail("--time-limit " + v + ": two limits for every scene");
          all_given = true;
          o.time_limits.all_s = d;
          o.time_limits.scene_s.clear();
        } else if (!valid_name(name, false)) {
          return fail("--time-limit " + v + ": bad scene name '" + name + "'");
        } else {
          scenes.emplace_back(name, d);
          limit_scenes.push_back(name);
        }
      }
      for (const auto& [name, d] : scenes) o.time_limits.scene_s[name] = d;
    } else if (a == "--out") {
      if (v.empty()) return fail("--out: empty folder name");
      o.out_dir = v;
    } else if (a == "--storey") {
      if (v.empty()) return fail("--storey: empty path");
      o.storey = v;
    } else if (a == "--config") {
      if (v.empty()) return fail("--config: empty path");
      o.config = v;
    }
  }
  if (!seeds_given)
    for (uint64_t s = 1; s <= 5; ++s) o.seeds.push_back(s);
  if (!o.presets.empty() && matrix_flag)
    return fail(matrix_flag_name +
                ": cannot be combined with --preset (a preset fixes the matrix)");
  if (o.presets.empty()) o.groups.push_back(flags);
  // Paper Section V: Tables I-II run every scene with every method; Tables III-IV run the
  // ablations of Groups A and B on maze with the proposed method.
  for (const auto& p : o.presets) {
    if (p == "tables" || p == "paper")
      o.groups.push_back({default_scenes(), default_methods(), {"full"}});
    if (p == "ablations" || p == "paper") {
      MatrixGroup g{{"maze"}, {"storey"}, ablations_group_a()};
      for (const auto& b : ablations_group_b())
        if (std::find(g.ablations.begin(), g.ablations.end(), b) == g.ablations.end())
          g.ablations.push_back(b);
      o.groups.push_back(g);
    }
  }
  // A limit for a scene the matrix does not run is a typo that would pass silently.
  for (const auto& name : limit_scenes) {
    bool found = false;
    std::string known = ", ";
    for (const auto& g : o.groups)
      for (const auto& s : g.scenes) {
        const std::string stem = RunSpec{s, "", "", 1}.scene_name();
        found = found || stem == name;
        if (known.find(", " + stem + ",") != std::string::npos) continue;  // maze in two groups
        known += stem + ", ";
      }
    if (!found)
      return fail("--time-limit: scene '" + name +
                  "' is not in the matrix (scenes: " + known.substr(2, known.size() - 4) + ")");
  }
  return r;
}

}  // namespace storey::tools::eval
