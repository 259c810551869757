// Exploration metrics against the ground truth (paper Section V, DESIGN §7): coverage of the
// ground-truth traversable voxels by observed ones (1-voxel vertical tolerance), per floor,
// volumes, coverage over time, and the metrics.json writer.
#pragma once

#include <string>
#include <vector>

#include "tools/sim/ground_truth.hpp"

namespace storey::tools::sim {

struct Coverage {
  double traversable_coverage = 0.0;          // 0..1 of ground-truth reachable support voxels
  std::vector<double> per_floor;              // 0..1, indexed like gt.floors()
  double observed_traversable_volume_m3 = 0;  // observed traversable voxels x res^3
  double observed_occupied_volume_m3 = 0;     // observed occupied voxels x res^3
};

// A ground-truth traversable voxel counts as covered when an observed traversable voxel lies at
// the same (x, y) within +-1 voxel in z (the map and the truth may round a surface apart).
Coverage compute_coverage(const GroundTruth& gt, const std::vector<VoxelKey>& observed_traversable,
                          const std::vector<VoxelKey>& observed_occupied = {});

// Coverage as the robot explores: add samples, query the time each floor reached a fraction.
class CoverageTimeline {
 public:
  struct Sample {
    double t;
    double coverage;
    std::vector<double> per_floor;
  };
  void add(double t, const Coverage& c) {
    samples_.push_back({t, c.traversable_coverage, c.per_floor});
  }
  const std::vector<Sample>& samples() const { return samples_; }
  // First time floor f (or overall when f < 0) reached `fraction`; negative when never.
  double time_to(double fraction, int f = -1) const;

 private:
  std::vector<Sample> samples_;
};

struct FloorMetrics {
  double z_m = 0.0, time_s = 0.0, traversable_coverage = 0.0;
};
struct LatencyMetrics {
  std::string task;
  double p50_ms = 0.0, p99_ms = 0.0, max_ms = 0.0;
  uint64_t overruns = 0;
};
// How far the body strayed from its reference pose on the trajectory it followed (every 10 ms
// of simulated time while one was followed). The planner and the control look-ahead check the
// reference's poses, not the body's: `side` is the body's distance to the reference's left or
// right, `ahead` how far it ran ahead of the reference along its heading.
struct TrackingMetrics {
  double side_p50_m = 0.0, side_p99_m = 0.0, side_max_m = 0.0, ahead_max_m = 0.0;
  uint64_t samples = 0;
};
// DESIGN §7 metrics.json. The simulator fills the truth-derived fields; the firmware the rest.
struct RunMetrics {
  bool success = false;
  // What ran and how it ended (storey-eval reads end_reason): the exploration method
  // (exploration_policy.hpp), the ablation ("" = none), whether the planner reported exploration
  // complete, and the one-line reason the run ended.
  std::string method = "storey", ablation, end_reason;
  std::string commit;  // the storey build's commit (firmware::build_commit())
  bool completed = false;
  int floors_total = 0, floors_explored = 0;
  double exploration_time_s = 0.0, trajectory_length_m = 0.0;
  double walking_time_s = 0.0;  // of exploration_time_s, moving at > kWalkingSpeed (0.2 m/s)
  double traversable_volume_m3 = 0.0, occupied_volume_m3 = 0.0;        // observed
  double gt_traversable_volume_m3 = 0.0, gt_occupied_volume_m3 = 0.0;  // ground truth
  double traversable_coverage = 0.0;
  std::vector<FloorMetrics> per_floor;
  uint32_t collisions = 0, falls = 0, safety_stops = 0;
  TrackingMetrics tracking;
  std::vector<LatencyMetrics> latency;
  std::vector<std::pair<double, double>> coverage_over_time;  // (t [s], coverage 0..1)
};

// Fills floors_total, gt volumes, coverage, per_floor (z, coverage; time_s from the timeline:
// first time the floor reached `floor_done` coverage) and coverage_over_time.
void fill_from_truth(const GroundTruth& gt, const Coverage& final_coverage,
                     const CoverageTimeline& timeline, double floor_done, RunMetrics& m);
std::string metrics_json(const RunMetrics& m);
// Throws std::runtime_error naming the file on failure.
void write_metrics_json(const RunMetrics& m, const std::string& path);

}  // namespace storey::tools::sim
