#include "core/graph/map_change_detector.hpp"

#include <algorithm>
#include <cmath>

namespace storey::core::graph {

using map::Cell;

MapChangeDetector::Sig MapChangeDetector::signature(const map::VoxelBlock& b, int16_t occ_q) const {
  Sig s;
  s.hash = 1469598103934665603ull;  // FNV-1a over one byte per voxel
  for (const Cell& c : b.cells) {
    const uint8_t occ = !(c.flags & Cell::kObserved) ? 0 : (c.log_odds > occ_q ? 2 : 1);
    const uint8_t v = uint8_t(occ | (uint8_t(c.state) << 2) | ((c.flags & Cell::kReachable) << 3));
    s.hash = (s.hash ^ v) * 1099511628211ull;
    s.occupied += occ == 2;
  }
  return s;
}

void MapChangeDetector::emit(std::vector<uint64_t>& cells, std::vector<Aabb>& out) {
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  for (uint64_t k : cells) {
    // Unpack the 21-bit two's complement coordinates.
    auto coord = [](uint64_t v) { return int32_t(uint32_t(v << 11)) >> 11; };
    const int32_t cx = coord((k >> 42) & 0x1FFFFF), cy = coord((k >> 21) & 0x1FFFFF),
                  cz = coord(k & 0x1FFFFF);
    Aabb b;
    b.lo = Eigen::Vector3f(float(cx), float(cy), float(cz)) * cell_m_;
    b.hi = b.lo + Eigen::Vector3f::Constant(cell_m_);
    out.push_back(b);
  }
}

size_t MapChangeDetector::detect(const map::MapView& view, std::span<const Aabb> regions,
                                 std::vector<Aabb>& out, std::vector<Aabb>* opened) {
  const int16_t occ_q = int16_t(std::lround(view.options().log_odds_occupied * map::kLogOddsScale));
  const double block_m = view.voxel_size_m() * map::kBlockDim;
  const map::BlockStore& store = view.store();
  cells_.clear();
  opened_cells_.clear();
  size_t changed = 0;
  auto check = [&](const map::VoxelBlock& b) {
    const uint64_t key = map::pack_block_key(b.bx, b.by, b.bz);
    const Sig s = signature(b, occ_q);
    auto [it, fresh] = sig_.try_emplace(key, s);
    if (!fresh && it->second.hash == s.hash) return;
    const bool lost = !fresh && s.occupied < it->second.occupied;
    it->second = s;
    ++changed;
    const Eigen::Vector3f centre =
        (Eigen::Vector3f(float(b.bx), float(b.by), float(b.bz)) + Eigen::Vector3f::Constant(0.5f)) *
        float(block_m);
    const int32_t cx = int32_t(std::floor(centre.x() / cell_m_));
    const int32_t cy = int32_t(std::floor(centre.y() / cell_m_));
    const int32_t cz = int32_t(std::floor(centre.z() / cell_m_));
    cells_.push_back(map::pack_block_key(cx, cy, cz));
    if (lost) opened_cells_.push_back(cells_.back());
  };
  for (const Aabb& r : regions) {
    if (r.empty()) continue;
    const int32_t x0 = int32_t(std::floor(r.lo.x() / block_m)),
                  x1 = int32_t(std::floor(r.hi.x() / block_m));
    const int32_t y0 = int32_t(std::floor(r.lo.y() / block_m)),
                  y1 = int32_t(std::floor(r.hi.y() / block_m));
    const int32_t z0 = int32_t(std::floor(r.lo.z() / block_m)),
                  z1 = int32_t(std::floor(r.hi.z() / block_m));
    const double volume = double(x1 - x0 + 1) * double(y1 - y0 + 1) * double(z1 - z0 + 1);
    if (volume > double(store.block_count())) {  // big region: walk the existing blocks
      store.for_each([&](const map::VoxelBlock& b) {
        if (b.bx >= x0 && b.bx <= x1 && b.by >= y0 && b.by <= y1 && b.bz >= z0 && b.bz <= z1)
          check(b);
      });
      continue;
    }
    for (int32_t bx = x0; bx <= x1; ++bx)
      for (int32_t by = y0; by <= y1; ++by)
        for (int32_t bz = z0; bz <= z1; ++bz)
          if (const map::VoxelBlock* b = store.find(map::pack_block_key(bx, by, bz))) check(*b);
  }
  emit(cells_, out);
  if (opened) emit(opened_cells_, *opened);
  return changed;
}

}  // namespace storey::core::graph
