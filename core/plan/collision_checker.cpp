#include "core/plan/collision_checker.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>

#include <algorithm>
#include <limits>

#include <Eigen/Geometry>

namespace storey::core::plan {

struct CollisionChecker::Impl {
  std::shared_ptr<fcl::Boxd> body_geom;
  std::unique_ptr<fcl::CollisionObjectd> body;
  // Voxel objects are pooled and re-positioned, never re-created once the pool has grown;
  // each has its own box (fitted to the voxel's points, MapView::VoxelExtent).
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> pool;
  std::vector<std::shared_ptr<fcl::Boxd>> pool_geom;
  std::vector<fcl::CollisionObjectd*> active;
  std::vector<float> surface_z;  // parallel to active
  fcl::DynamicAABBTreeCollisionManagerd manager;
};

namespace {
struct QueryData {
  const fcl::CollisionObjectd* body;
  const float* surface_z;  // per loaded voxel: mean height of its points (ground test)
  Eigen::Matrix3d r;       // body -> world rotation
  Eigen::Vector3d foot;
  double step;  // voxel centres less than this above the bottom face are ground
  bool hit = false;
  Eigen::Vector3d voxel = Eigen::Vector3d::Zero();
};

bool on_pair(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* data) {
  auto* q = static_cast<QueryData*>(data);
  const fcl::CollisionObjectd* vox = o1 == q->body ? o2 : o1;
  Eigen::Vector3d c = vox->getTranslation();
  c.z() = q->surface_z[reinterpret_cast<uintptr_t>(vox->getUserData())];
  if ((q->r.transpose() * (c - q->foot)).z() < q->step) return false;  // ground: keep looking
  c = vox->getTranslation();
  fcl::CollisionRequestd req;
  fcl::CollisionResultd res;
  if (fcl::collide(o1, o2, req, res) == 0) return false;
  q->hit = true;
  q->voxel = c;
  return true;  // stop at the first obstacle
}

bool finite(const BodyPose& p) {
  return p.foot_m.allFinite() && std::isfinite(p.yaw_rad) && std::isfinite(p.pitch_rad);
}

Eigen::Matrix3d body_rotation(const BodyPose& p) {
  // Nose up for positive pitch: rotate about the body's y axis by -pitch after the yaw.
  return (Eigen::AngleAxisd(p.yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(-p.pitch_rad, Eigen::Vector3d::UnitY()))
      .toRotationMatrix();
}
}  // namespace

CollisionChecker::CollisionChecker(const RobotModel& robot, double voxel_size_m,
                                   const CollisionOptions& options)
    : robot_(robot), opt_(options), voxel_m_(voxel_size_m), impl_(std::make_unique<Impl>()) {
  const double m = std::max(0.0, robot.body_margin_m);
  box_m_ = Eigen::Vector3d(robot.body_length_m + 2 * m, robot.body_width_m + 2 * m,
                           robot.body_height_m + m);
  max_spacing_m_ = 0.5 * box_m_.minCoeff();
  impl_->body_geom = std::make_shared<fcl::Boxd>(box_m_.x(), box_m_.y(), box_m_.z());
  impl_->body = std::make_unique<fcl::CollisionObjectd>(impl_->body_geom);
}

CollisionChecker::~CollisionChecker() = default;

double CollisionChecker::max_dt_s() const {
  const double spacing =
      opt_.sample_spacing_m > 0 ? std::min(opt_.sample_spacing_m, max_spacing_m_) : max_spacing_m_;
  const double half_diag = 0.5 * std::hypot(box_m_.x(), box_m_.y());
  const double sweep_speed =
      std::max({robot_.max_speed_mps, robot_.max_yaw_rate_rps * half_diag, 1e-3});
  return spacing / sweep_speed;
}

void CollisionChecker::load_voxels(std::span<const map::MapView::VoxelExtent> voxels,
                                   double ground_below_z) {
  Impl& im = *impl_;
  im.manager.clear();
  im.active.clear();
  im.surface_z.clear();
  for (const map::MapView::VoxelExtent& v : voxels) {
    if (double(v.surface_z_m) < ground_below_z) continue;  // ground for every pose of the group
    const size_t i = im.active.size();
    if (i == im.pool.size()) {
      im.pool_geom.push_back(std::make_shared<fcl::Boxd>(voxel_m_, voxel_m_, voxel_m_));
      im.pool.push_back(std::make_unique<fcl::CollisionObjectd>(im.pool_geom.back()));
    }
    fcl::Boxd& g = *im.pool_geom[i];
    g.side = 2.0 * v.half_m.cast<double>();
    g.computeLocalAABB();
    fcl::CollisionObjectd* o = im.pool[i].get();
    o->setTranslation(v.centre_m.cast<double>());
    o->setUserData(reinterpret_cast<void*>(uintptr_t(i)));
    im.surface_z.push_back(v.surface_z_m);
    o->computeAABB();
    im.active.push_back(o);
  }
  if (!im.active.empty()) im.manager.registerObjects(im.active);
  im.manager.setup();
}

double CollisionChecker::ground_floor_z(const BodyPose& p) const {
  const double half_diag = 0.5 * std::hypot(box_m_.x(), box_m_.y());
  return p.foot_m.z() + (robot_.step_height_m + opt_.ground_tolerance_m) * std::cos(p.pitch_rad) -
         half_diag * std::abs(std::sin(p.pitch_rad));
}

bool CollisionChecker::collide_one(const BodyPose& p, Eigen::Vector3d* voxel) {
  Impl& im = *impl_;
  if (im.active.empty()) return false;
  const Eigen::Matrix3d r = body_rotation(p);
  im.body->setTransform(r, p.foot_m + r * Eigen::Vector3d(0, 0, 0.5 * box_m_.z()));
  im.body->computeAABB();
  QueryData q{im.body.get(), im.surface_z.data(), r, p.foot_m,
              robot_.step_height_m + opt_.ground_tolerance_m};
  im.manager.collide(im.body.get(), &q, on_pair);
  if (q.hit && voxel) *voxel = q.voxel;
  return q.hit;
}

CollisionHit CollisionChecker::check_poses(std::span<const BodyPose> poses,
                                           std::span<const Eigen::Vector3f> voxel_centres_m) {
  CollisionHit h;
  double ground = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < poses.size(); ++i) {
    if (!finite(poses[i])) {
      h.collides = h.bad_input = true;
      h.sample = i;
      h.t_s = poses[i].t_s;
      return h;
    }
    ground = std::min(ground, ground_floor_z(poses[i]));
  }
  extents_.clear();
  for (const Eigen::Vector3f& c : voxel_centres_m)
    extents_.push_back({c, Eigen::Vector3f::Constant(float(0.5 * voxel_m_)), c.z()});
  load_voxels(extents_, ground);
  h.voxels_loaded = uint32_t(impl_->active.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    ++h.poses_checked;
    if (collide_one(poses[i], &h.voxel_m)) {
      h.collides = true;
      h.sample = i;
      h.t_s = poses[i].t_s;
      return h;
    }
  }
  return h;
}

namespace {
// Below this the floor's surface noise (a few cm over the body length) would tilt the box on
// flat ground; stairs (~30 deg) and ramps are well above it.
constexpr double kMinTerrainPitchRad = 0.1;
}  // namespace

std::optional<double> CollisionChecker::terrain_pitch(const map::MapView& view, const BodyPose& p,
                                                      double* mid_z) const {
  const double half = 0.5 * robot_.body_length_m;
  const Eigen::Vector3d fwd(std::cos(p.yaw_rad), std::sin(p.yaw_rad), 0);
  // Slope window: the body's half length at 40 deg plus a step.
  const double window = half * 0.84 + robot_.step_height_m;
  const auto front = view.support_surface_near((p.foot_m + half * fwd).cast<float>(), window);
  const auto back = view.support_surface_near((p.foot_m - half * fwd).cast<float>(), window);
  if (!front && !back) return std::nullopt;
  // One end unseen (the LiDAR's blind ring around the robot): with the seen end higher than the
  // foot (front legs on a tread, rear ones on the floor unseen under the body) the unseen end
  // stands at the foot's height. With the seen end lower, the pose's own pitch stands: the foot
  // may lie above ground never seen (the top of a flight climbed blind, the foot on the line
  // over the nosings), and the foot's height there pitched the body nose down into the landing.
  const double zf = front ? double(front->height_m) : p.foot_m.z();
  const double zb = back ? double(back->height_m) : p.foot_m.z();
  if (std::max(zf, zb) <= p.foot_m.z() && (!front || !back)) {
    // ... but not so steep that the seen end's legs stand below its support: a walk from the
    // top tread onto a landing over the unseen tread between rises 0.33 m in 0.3 m, and at that
    // pose pitch (48 deg) the rear of the body dipped into the tread it stood on (office seed 1
    // with graph.close_probes_at_wall_faces, session 25: the climb onto the landing refused).
    const double up = std::atan2(p.foot_m.z() - zb, half);     // rear on its support
    const double down = -std::atan2(p.foot_m.z() - zf, half);  // front on its support
    if (back && p.pitch_rad > up) return up;
    if (front && p.pitch_rad < down) return down;
    return std::nullopt;
  }
  if (mid_z) *mid_z = 0.5 * (zf + zb);
  return std::atan2(zf - zb, 2.0 * half);
}

CollisionHit CollisionChecker::check_poses(const map::MapView& view,
                                           std::span<const BodyPose> in_poses) {
  adjusted_.assign(in_poses.begin(), in_poses.end());
  for (BodyPose& p : adjusted_)
    if (finite(p))
      if (double mid = 0; const auto tp = terrain_pitch(view, p, &mid)) {
        if (std::abs(*tp) < kMinTerrainPitchRad) {
          // Level under both ends: the body stands level too, whatever the path's chord says
          // (a climb's first pose at the flight's foot is pitched up the flight; at 27 deg the
          // rear of the box dipped into the floor behind, session 39).
          p.pitch_rad = std::clamp(p.pitch_rad, -kMinTerrainPitchRad, kMinTerrainPitchRad);
          continue;
        }
        p.pitch_rad = *tp;
        p.foot_m.z() = std::max(p.foot_m.z(), mid);
      }
  const std::span<const BodyPose> poses(adjusted_);
  CollisionHit h;
  const double half_diag = 0.5 * std::hypot(box_m_.x(), box_m_.y());
  const double pad = half_diag + voxel_m_;
  size_t i = 0;
  while (i < poses.size()) {
    // Group consecutive poses while their bounding box stays within chunk_extent_m.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    double ground = std::numeric_limits<double>::infinity();
    size_t j = i;
    for (; j < poses.size(); ++j) {
      const BodyPose& p = poses[j];
      if (!finite(p)) {
        if (j > i) break;  // check the finite ones first, then report the bad pose
        h.collides = h.bad_input = true;
        h.sample = j;
        h.t_s = p.t_s;
        return h;
      }
      const Eigen::Vector3d nlo = lo.cwiseMin(p.foot_m), nhi = hi.cwiseMax(p.foot_m);
      if (j > i && (nhi - nlo).head<2>().maxCoeff() > opt_.chunk_extent_m) break;
      lo = nlo;
      hi = nhi;
      ground = std::min(ground, ground_floor_z(p));
    }
    // Padded by the half diagonal: covers the box at any yaw and at pitches up to 90 deg.
    const Eigen::Vector3d blo = lo - Eigen::Vector3d::Constant(pad);
    const Eigen::Vector3d bhi = hi + Eigen::Vector3d(pad, pad, box_m_.z() + pad);
    extents_.clear();
    view.occupied_extents_in_box(((blo + bhi) * 0.5).cast<float>(),
                                 ((bhi - blo) * 0.5).cast<float>(), extents_);
    load_voxels(extents_, ground);
    h.voxels_loaded += uint32_t(impl_->active.size());
    for (size_t k = i; k < j; ++k) {
      ++h.poses_checked;
      if (collide_one(poses[k], &h.voxel_m)) {
        h.collides = true;
        h.sample = k;
        h.t_s = poses[k].t_s;
        return h;
      }
    }
    i = j;
  }
  return h;
}

CollisionHit CollisionChecker::check_segment(const map::MapView& view, const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b, double yaw_rad) {
  const Eigen::Vector3d d = b - a;
  const double len = d.head<2>().norm();
  const double yaw = std::isfinite(yaw_rad) ? yaw_rad : len > 1e-9 ? std::atan2(d.y(), d.x()) : 0.0;
  // Pitch along the heading: the climb over the horizontal run in the body's forward direction.
  const double fwd = d.x() * std::cos(yaw) + d.y() * std::sin(yaw);
  const double pitch = len > 1e-9 ? std::atan2(d.z() * (fwd >= 0 ? 1 : -1), len) : 0.0;
  const double spacing =
      opt_.sample_spacing_m > 0 ? std::min(opt_.sample_spacing_m, max_spacing_m_) : max_spacing_m_;
  const int n = std::max(1, int(std::ceil(d.norm() / spacing)));
  samples_.clear();
  for (int i = 0; i <= n; ++i) {
    const double s = double(i) / n;
    samples_.push_back({a + s * d, yaw, pitch, s});
  }
  return check_poses(view, samples_);
}

}  // namespace storey::core::plan
