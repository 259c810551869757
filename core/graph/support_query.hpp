#pragma once
// Support-surface queries of the reachable graph on top of MapView primitives (paper III-B):
// projection of a candidate onto the local ground, node classification (confirmed, tentative,
// invalid) and edge validation as a walk over the support surface. One SupportQuery caches the
// last map block it read: build it per update cycle over the view of that cycle, never keep it
// across a write to the map (same invalidation rule as map::BlockReader).
#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "core/graph/graph_options.hpp"
#include "core/map/map_view.hpp"

namespace storey::core::graph {

// Element states of the paper (Sec. III-B; S_hyp is used by the hybrid graph of Sec. IV-B).
enum class ElementState : uint8_t { kConfirmed = 0, kTentative = 1, kHypothetical = 2 };

struct Support {
  Eigen::Vector3f p_m = Eigen::Vector3f::Zero();  // (x, y, surface height)
  map::VoxelKey key;                              // the support voxel
  map::TravState state = map::TravState::kNone;   // tau(v), Eq. 3
  bool reachable = false;                         // v in C_reach
  float cost = 0;                                 // c(v), Eq. 2
  // v was seen only from below (MapOptions::floor_seen_from_above): a slab's underside,
  // whatever lies above it not yet observed.
  bool underside = false;
};

// Why an element is invalid (diagnostics, counted by the graph).
enum class Reject : uint8_t {
  kNone = 0,
  kNoSupport,      // no support surface where one is needed
  kUntraversable,  // support voxel is S_untrav
  kCollision,      // occupied voxel inside the body clearance
  kFallRisk,       // observed drop next to / under the path
  kStep,           // height change between samples beyond the step height
  kSlope,          // mean grade beyond max_edge_slope_rad
  kGap,            // unknown ground longer than max_gap_m
  kNotReachable,   // use_tentative = false and not in C_reach
  kCount
};

struct EdgeCheck {
  Reject reject = Reject::kNone;
  bool all_reachable = false;  // every sample's support voxel is in C_reach (no gap)
  float length_m = 0;          // 3D length along the samples
  float mean_cost = 0;         // mean c(v) over the supported samples
  bool valid() const { return reject == Reject::kNone; }
};

class SupportQuery {
 public:
  SupportQuery(const map::MapView& view, const GraphOptions& opt);

  map::Occupancy occupancy(const map::VoxelKey& k);
  bool reachable(const map::VoxelKey& k) {  // v in C_reach
    const map::Cell* c = cell(k);
    return c && (c->flags & map::Cell::kReachable);
  }
  // The support voxel in the column under (x, y) whose surface height is closest to z, within
  // +-window_m; nullopt if none.
  std::optional<Support> surface_near(float x, float y, float z, float window_m);
  // surface_near, but if the column's support is not in C_reach, the best support of the 8
  // neighbour columns within the window may stand in for it (reachable > traversable >
  // under-observed > untraversable, then nearest in height). The map's surfaces are 0.1 m
  // voxels: a stair nose or a box border shares a voxel with a riser and is rough there, while
  // the legs simply step over it; C_reach itself connects through the neighbour columns.
  std::optional<Support> support_dilated(float x, float y, float z, float window_m);
  // Body clearance over a support point: no occupied voxel between one step above the surface
  // and the body height (+ margin), in the column and at +-(half width + margin) along
  // `lateral` (unit, horizontal). Unknown voxels are no evidence (tentative elements).
  bool body_clear(float x, float y, float h, const Eigen::Vector2f& lateral);
  // Fall risk next to a support point: observed drops (free at the surface level, no support
  // within a step) in at least two of eight directions at the body's half width.
  bool fall_risk(const Eigen::Vector3f& p);
  // Node verdict: kNone and `confirmed` set if fully supported by C_reach, else the reason.
  Reject classify_node(const Support& s, bool* confirmed);
  // Edge as a walk over the support surface at voxel spacing (stairs are sequences of small
  // steps; a jump between floors or through a slab never passes).
  EdgeCheck check_edge(const Eigen::Vector3f& a, const Eigen::Vector3f& b);

  // Walks the segment (voxel DDA, the voxel of `from` excluded) and returns the occupancy of
  // the first voxel that is occupied, or unknown if stop_at_unknown; kFree if none. `free_m`
  // receives the distance walked through known free space before it.
  map::Occupancy walk(const Eigen::Vector3f& from, const Eigen::Vector3f& to, bool stop_at_unknown,
                      float* free_m = nullptr);

  // C_exp probe: walks from -> to; open if it starts with at least min_free_m of known free
  // space, hits nothing occupied, and ends in an unknown region (the last min_unknown_m of the
  // probe unknown). Unknown holes enclosed by free space (gaps in the ray coverage) are not
  // regions and do not open a probe.
  bool probe_open(const Eigen::Vector3f& from, const Eigen::Vector3f& to, float min_free_m,
                  float min_unknown_m);

  // C_exp probe over rising terrain (stairs, ramps): walks from `foot` along the horizontal unit
  // `dir` at `height_m` above the current support. An obstacle whose top is a support within
  // two steps above the current one (and within the edge slope) is climbed: the probe continues
  // at height_m above it. Climbing onto under-observed support (S_unobs: a tread seen only
  // edge-on from below) or meeting an obstacle with unknown space right above it counts as
  // reaching unobserved terrain (open). Otherwise as probe_open. Without this, a stair's risers
  // close every probe at body height up the flight and the stairs never become a frontier (paper
  // III-C: stairs are the way to the next floor). `climbed` (optional) tells whether an open
  // probe had climbed two stair steps (each steeper than 25 deg) first: it runs up a flight; or,
  // with GraphOptions::ramp_frontiers, whether its support rose a step height on the way in
  // climbs flatter than a stair's: it runs up a ramp.
  // *leaves_reach: the probe climbed a flight (two stair steps) onto support out of C_reach.
  // *blocked: a closed probe ended at an obstacle it could not climb or at a hole in a surface
  // (close_probes_at_holes): a wall.
  // *why (diagnostics, optional): which unknown opened the probe and where.
  enum class OpenBy : uint8_t { kNone = 0, kUnknownRun, kUnobservedStep, kUnknownOverObstacle };
  struct ProbeWhy {
    OpenBy by = OpenBy::kNone;
    Eigen::Vector3f at_m = Eigen::Vector3f::Zero();  // the unknown run's first voxel / the step
  };
  bool probe_open_climbing(const Eigen::Vector3f& foot, const Eigen::Vector2f& dir, float length_m,
                           float height_m, float min_free_m, float min_unknown_m,
                           bool* climbed = nullptr, bool* leaves_reach = nullptr,
                           bool* blocked = nullptr, ProbeWhy* why = nullptr);

  const map::MapView& view() const { return view_; }
  float voxel_size() const { return vs_; }
  float step() const { return step_; }

 private:
  bool underside(const map::Cell& c, const map::VoxelStats* st) const;
  // One straight leg of a C_exp probe: counts free voxels and the current unknown run (carried
  // over between legs); stops at the first occupied voxel (hit) or at unknown space met before
  // need_free free voxels (closed).
  struct ProbeSegment {
    bool hit = false, closed = false;
    bool hole = false;  // closed at a hole in a surface (close_probes_at_holes): a wall
    map::VoxelKey hit_key{};
    map::VoxelKey run_start{};  // first voxel of the unknown run this leg began or extended
  };
  ProbeSegment probe_segment(const Eigen::Vector3f& from, const Eigen::Vector3f& to, int need_free,
                             int* free_total, int* unknown_run);
  // `top` lies on a wall's face, no step: the obstacle rises on behind it (one or two voxels
  // further along dir, the two voxels over top's height occupied). A face that straddles a voxel
  // boundary is hit at some heights only, and each hit voxel with free space over it looks
  // like a tread seen edge-on (teaching_building: C_exp frontiers along explored rooms' walls).
  bool wall_face(const Support& top, const Eigen::Vector2f& dir);
  // Unknown voxel k between two occupied voxels on one axis: a gap in a surface.
  bool hole_in_surface(const map::VoxelKey& k);

  const map::Cell* cell(const map::VoxelKey& k) { return reader_.cell(k); }
  bool occupied(const map::Cell* c) const {
    return c && (c->flags & map::Cell::kObserved) && c->log_odds > occ_q_;
  }
  bool free(const map::Cell* c) const {
    return c && (c->flags & map::Cell::kObserved) && c->log_odds <= occ_q_;
  }
  int32_t zkey(float z) const;

  map::MapView view_;
  map::BlockReader reader_;
  const GraphOptions& opt_;
  int16_t occ_q_;
  float vs_, inv_vs_, step_, col_lo_, clear_, lateral_m_, tan_slope_;
};

}  // namespace storey::core::graph
