#include "core/graph/viewpoint_generator.hpp"

#include <algorithm>
#include <cmath>

namespace storey::core::graph {

bool ViewpointGenerator::visible(SupportQuery& q, const Eigen::Vector3f& origin, float yaw,
                                 const Eigen::Vector3f& target) const {
  const Eigen::Vector3f d = target - origin;
  const float horiz = std::hypot(d.x(), d.y());
  if (d.norm() > float(fov_.max_range_m)) return false;
  const float el = std::atan2(d.z(), horiz) * float(180.0 / M_PI);
  if (el < float(fov_.v_min_deg) || el > float(fov_.v_max_deg)) return false;
  if (fov_.h_fov_deg < 360.0) {
    const float az = std::remainder(std::atan2(d.y(), d.x()) - yaw, 2.0f * float(M_PI));
    if (std::abs(az) * float(180.0 / M_PI) > float(0.5 * fov_.h_fov_deg)) return false;
  }
  return q.walk(origin, target, false) != map::Occupancy::kOccupied;
}

void ViewpointGenerator::generate(const ReachableGraph& g, const map::MapView& view,
                                  const FrontierCluster& c, std::vector<Viewpoint>& out) {
  out.clear();
  if (c.nodes.empty()) return;
  SupportQuery q(view, opt_);
  const float r = float(opt_.viewpoint_radius_m);
  cand_.clear();
  g.nodes_within(c.centroid_m, r, r, cand_);
  cand_.insert(cand_.end(), c.nodes.begin(), c.nodes.end());
  std::sort(cand_.begin(), cand_.end());
  cand_.erase(std::unique(cand_.begin(), cand_.end()), cand_.end());
  const Eigen::Vector3f up(0, 0, float(fov_.mount_height_m));
  const Eigen::Vector3f aim(0, 0, float(opt_.viewpoint_target_height_m));
  scored_.clear();
  for (NodeId n : cand_) {
    const GraphNode& gn = g.node(n);
    if (!gn.alive) continue;
    Viewpoint v;
    v.node = n;
    v.p_m = gn.p_m;
    v.state = gn.state;
    const Eigen::Vector3f to_c = c.centroid_m - gn.p_m;
    v.yaw_rad = std::hypot(to_c.x(), to_c.y()) > 1e-3f ? std::atan2(to_c.y(), to_c.x()) : 0.0f;
    const Eigen::Vector3f origin = gn.p_m + up;
    for (NodeId t : c.nodes) v.visible += visible(q, origin, v.yaw_rad, g.node(t).p_m + aim);
    if (v.visible > 0) scored_.push_back(v);
  }
  // Most visible first; confirmed before tentative; then nearer the centroid; then id.
  std::sort(scored_.begin(), scored_.end(), [&](const Viewpoint& a, const Viewpoint& b) {
    if (a.visible != b.visible) return a.visible > b.visible;
    if (a.state != b.state) return a.state < b.state;
    const float da = (a.p_m - c.centroid_m).squaredNorm(),
                db = (b.p_m - c.centroid_m).squaredNorm();
    if (da != db) return da < db;
    return a.node < b.node;
  });
  const size_t k = size_t(std::max(1, opt_.viewpoints_per_cluster));
  out.assign(scored_.begin(), scored_.begin() + std::min(k, scored_.size()));
}

const std::vector<ClusterViewpoints>& ViewpointGenerator::update(
    const ReachableGraph& g, const map::MapView& view,
    const std::vector<FrontierCluster>& clusters) {
  out_.resize(clusters.size());
  for (size_t i = 0; i < clusters.size(); ++i) {
    out_[i].cluster_id = clusters[i].id;
    generate(g, view, clusters[i], out_[i].viewpoints);
  }
  return out_;
}

}  // namespace storey::core::graph
