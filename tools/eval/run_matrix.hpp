// The evaluation matrix: scenes x methods x ablations x seeds (paper Section V), one RunSpec per
// `storey sim` run, each with its own folder DIR/runs/<scene>/<method>[-<ablation>]/seed<N>.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace storey::tools::eval {

// Simulated seconds per run: one for every scene, or a scene's own (keyed by
// RunSpec::scene_name()). The teaching building gets 3000 s by default: our robot explores it in
// ~2000 s (docs/RESULTS.md, session 43), so the common 1800 s would cut every seed short; the
// baselines end there long before 1800 s, so their rows do not depend on it.
struct TimeLimits {
  double all_s = 1800;
  std::map<std::string, double> scene_s = {{"teaching_building", 3000}};
  double for_scene(const std::string& scene_name) const {
    const auto it = scene_s.find(scene_name);
    return it == scene_s.end() ? all_s : it->second;
  }
  // "1800 s, teaching_building 3000 s"
  std::string describe() const;
};
// A --time-limit value: the whole string a finite number of seconds > 0.
bool parse_seconds(const std::string& s, double& out);

// One block of the matrix. "full" in `ablations` means the method without --ablation.
struct MatrixGroup {
  std::vector<std::string> scenes, methods, ablations;
};

struct RunSpec {
  std::string scene;     // as passed to --scene (a built-in name or a file)
  std::string method;    // --method
  std::string ablation;  // --ablation; "" = full method
  uint64_t seed = 1;

  // "storey" or "storey-no-c-sur": the folder and table row name.
  std::string variant() const { return ablation.empty() ? method : method + "-" + ablation; }
  // Folder-safe scene name: the file stem for a path ("scenes/my.yaml" -> "my").
  std::string scene_name() const;
  // "runs/<scene>/<variant>/seed<N>", relative to the output folder.
  std::string rel_dir() const;
  // The `storey sim` arguments after the executable (argv[1..]).
  std::vector<std::string> sim_args(double time_limit_s, const std::string& out_dir,
                                    const std::string& config) const;
  bool operator==(const RunSpec&) const = default;
};

// Expands every group over `seeds`, in order (group, scene, method, ablation, seed); a run that
// two groups share appears once, where it first appears.
std::vector<RunSpec> expand_matrix(const std::vector<MatrixGroup>& groups,
                                   const std::vector<uint64_t>& seeds);

// The paper's configurations (Section V-B): Table III (Group A, first floor of maze) and Table IV
// (Group B, second floor of maze).
const std::vector<std::string>& ablations_group_a();  // full, no-tentative, ... boundary-frontiers
const std::vector<std::string>& ablations_group_b();  // full, no-prior, no-incremental

}  // namespace storey::tools::eval
