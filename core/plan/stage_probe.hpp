#pragma once
// Per-stage profiling hook of the planning cycle. core/ reads no clock: the caller (a benchmark,
// the firmware's perf counters) implements mark() with its own clock and attributes the time
// since the previous mark to the previous stage. The planner only calls mark() when a probe is
// set; it never reads anything back, so a probe cannot change a decision.
#include <cstdint>

namespace storey::core::plan {

enum class PlanStage : uint8_t {
  kFloors = 0,     // floor tracking and per-floor progress
  kPrior,          // reference floor's graph + obstacle clearance per node (zone seeds, IV-A)
  kPriorZones,     // task zones on the reference floor + projection into G_hyp (IV-A)
  kHybridBind,     // IV-B 1: real nodes absorb overlapping hypotheses
  kHybridCheck,    // IV-B 1: hypotheses and hypothetical edges against the new map
  kHybridCompile,  // G_real + G_hyp (+ bridges) -> CSR
  kHybridZones,    // IV-B 2: split / reassign / merge, zone states
  kGlobal,         // IV-C: two-stage cost rows + zone TSP
  kLocalKeep,      // local layer: keep-or-replan test of the current target
  kLocalStage1,    // IV-D Stage 1: search graph, cluster costs, TSP
  kLocalStage2,    // IV-D Stage 2: viewpoint DP (Eq. 6)
  kLocalStage3,    // IV-D Stage 3: voxel A* + B-spline + FCL
  kApproach,       // IV-C real prefix toward a zone centre (two-stage A*, voxel A*, B-spline)
  kDone,           // end of the cycle
  kCount
};
const char* to_string(PlanStage s);

class StageProbe {
 public:
  virtual ~StageProbe() = default;
  // From now on, time belongs to stage `s`.
  virtual void mark(PlanStage s) = 0;
};

// Null-safe helper for the planner's classes.
inline void probe_mark(StageProbe* p, PlanStage s) {
  if (p) p->mark(s);
}

}  // namespace storey::core::plan
