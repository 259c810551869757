#include "tools/eval/run_matrix.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace storey::tools::eval {

std::string RunSpec::scene_name() const {
  std::string n = scene;
  const size_t slash = n.find_last_of('/');
  if (slash != std::string::npos) n = n.substr(slash + 1);
  const size_t dot = n.find('.');
  if (dot != std::string::npos && dot > 0) n = n.substr(0, dot);
  return n;
}

std::string RunSpec::rel_dir() const {
  return "runs/" + scene_name() + "/" + variant() + "/seed" + std::to_string(seed);
}

bool parse_seconds(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return !s.empty() && end && *end == '\0' && std::isfinite(out) && out > 0;
}

std::string TimeLimits::describe() const {
  char b[64];
  std::snprintf(b, sizeof b, "%g s", all_s);
  std::string s = b;
  for (const auto& [scene, t] : scene_s) {
    std::snprintf(b, sizeof b, "%g s", t);
    s += ", " + scene + " " + b;
  }
  return s;
}

std::vector<std::string> RunSpec::sim_args(double time_limit_s, const std::string& out_dir,
                                           const std::string& config) const {
  char t[32];
  std::snprintf(t, sizeof t, "%g", time_limit_s);
  std::vector<std::string> a = {"sim", "--scene", scene, "--method", method};
  if (!ablation.empty()) {
    a.push_back("--ablation");
    a.push_back(ablation);
  }
  for (const std::string& s :
       {std::string("--seed"), std::to_string(seed), std::string("--time-limit"), std::string(t),
        std::string("--out"), out_dir})
    a.push_back(s);
  if (!config.empty()) {
    a.push_back("--config");
    a.push_back(config);
  }
  return a;
}

std::vector<RunSpec> expand_matrix(const std::vector<MatrixGroup>& groups,
                                   const std::vector<uint64_t>& seeds) {
  std::vector<RunSpec> out;
  for (const auto& g : groups)
    for (const auto& scene : g.scenes)
      for (const auto& method : g.methods)
        for (const auto& ab : g.ablations)
          for (const uint64_t seed : seeds) {
            RunSpec r{scene, method, ab == "full" ? std::string() : ab, seed};
            if (std::find(out.begin(), out.end(), r) == out.end()) out.push_back(std::move(r));
          }
  return out;
}

const std::vector<std::string>& ablations_group_a() {
  static const std::vector<std::string> a = {"full", "no-tentative", "no-c-sur", "no-c-exp",
                                             "boundary-frontiers"};
  return a;
}
const std::vector<std::string>& ablations_group_b() {
  static const std::vector<std::string> b = {"full", "no-prior", "no-incremental"};
  return b;
}

}  // namespace storey::tools::eval
