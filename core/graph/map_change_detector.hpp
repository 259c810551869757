#pragma once
// Which parts of the map changed in a way the graph can see (paper Sec. III-B: "upon each map
// update, the affected local subgraph is re-evaluated"). The map reports no change set yet, so
// this keeps a 64-bit signature per 8^3 voxel block of what the graph's queries read (occupancy
// class, tau(v), C_reach membership of every voxel; not the point statistics, which grow with
// every return) and compares the blocks inside the given regions (e.g. the scan's bounds) with
// the previous call. Changed blocks are reported as boxes of coarse super-cells (merged), which
// ReachableGraph::update and TopologicalFrontiers::update take as their changed regions.
// Cost: one pass over the existing blocks inside the regions (~0.5 us per block).
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "core/graph/reachable_graph.hpp"
#include "core/map/map_view.hpp"

namespace storey::core::graph {

class MapChangeDetector {
 public:
  explicit MapChangeDetector(float super_cell_m = 1.6f) : cell_m_(super_cell_m) {}
  // Appends to `out` one box per super-cell holding a changed block, and to `opened` (if
  // given) one per super-cell holding a block that lost occupied voxels (something was removed:
  // a door opened, an obstacle left); returns the number of changed blocks.
  size_t detect(const map::MapView& view, std::span<const Aabb> regions, std::vector<Aabb>& out,
                std::vector<Aabb>* opened = nullptr);
  size_t tracked_blocks() const { return sig_.size(); }

 private:
  struct Sig {
    uint64_t hash = 0;
    uint32_t occupied = 0;
  };
  Sig signature(const map::VoxelBlock& b, int16_t occ_q) const;
  void emit(std::vector<uint64_t>& cells, std::vector<Aabb>& out);
  float cell_m_;
  std::unordered_map<uint64_t, Sig> sig_;
  std::vector<uint64_t> cells_, opened_cells_;
};

}  // namespace storey::core::graph
