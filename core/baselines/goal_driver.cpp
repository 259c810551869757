#include "core/baselines/goal_driver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/plan/escape.hpp"
#include "core/plan/local_planner.hpp"
#include "core/plan/path_centring.hpp"
#include "core/plan/plan_config.hpp"

namespace storey::core::baselines {

namespace {
double dist_xy(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a - b).head<2>().norm();
}
bool near(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) {
  return dist_xy(a, b) <= r && std::abs(a.z() - b.z()) < 0.5;
}
}  // namespace

GoalDriver::GoalDriver(const RobotModel& robot, const plan::PlanOptions& plan, double voxel_size_m,
                       const BaselineOptions& options)
    : robot_(robot),
      opt_(options),
      astar_(plan::astar_options(plan)),
      builder_(robot, plan::trajectory_options(plan)),
      checker_(robot, voxel_size_m),
      no_progress_s_(plan.no_progress_s),
      arrive_along_path_(plan.arrive_along_path) {}

bool GoalDriver::set_aside(const Eigen::Vector3d& key_m) const {
  for (const Eigen::Vector3d& s : set_aside_)
    if (near(s, key_m, opt_.set_aside_radius_m)) return true;
  return false;
}

bool GoalDriver::set_aside(const Goal& g) const {
  // Frontier clusters change shape as the map grows (their centroid moves): a goal is also set
  // aside when the place to stand is one where the robot already stood or failed.
  return set_aside(g.key_m) || set_aside(g.p_m);
}

bool GoalDriver::keep(const plan::ExplorationInput& in, const std::vector<Goal>& goals,
                      plan::ExplorationResult& r) {
  // An escape walk runs to its end, as the local layer's does (committed): replaced by the next
  // cycle's trajectory to a goal, it moved the body 0.1 m and the robot stayed wedged at a maze
  // wall's end (maze seed 2, tare-like).
  if (escaping_) {
    if (in.t_s <= escape_end_s_ + 1.0 && dist_xy(in.robot_foot_m, escape_to_m_) > 0.05) {
      r.status = plan::ExplorationStatus::kKeep;
      r.reason = "escape walk";
      r.target_m = escape_to_m_;
      r.target_yaw_rad = in.robot_yaw_rad;
      return true;
    }
    escaping_ = false;
  }
  // As the local layer does: a robot that stood still with a target for no_progress_s (a body
  // wedged at a wall corner, replanning the same target every replan_period_s: maze seed 2,
  // tare-like, from 600 s to the limit) sets the target aside and steps away from what it meets.
  if (progress_.stalled(in.robot_foot_m, in.robot_yaw_rad, in.t_s, has_target_, no_progress_s_)) {
    add_set_aside(target_.key_m), add_set_aside(target_.p_m);
    ++counts_.no_progress;
    has_target_ = false;
    return escape_away_from(
        in, plan::blocking_point(*in.view, robot_, in.robot_foot_m, in.robot_yaw_rad),
        "escape: no progress, away from what the body meets", r);
  }
  if (!has_target_) return false;
  bool still_goal = false;
  for (const Goal& g : goals) still_goal = still_goal || near(g.key_m, target_.key_m, 0.5);
  const bool reached = dist_xy(in.robot_foot_m, target_.p_m) <= opt_.reached_radius_m &&
                       std::abs(in.robot_foot_m.z() - target_.p_m.z()) < 0.5;
  if (reached) {
    has_target_ = false;
    if (!still_goal) return false;
    if (approach_frontier_ && dist_xy(target_.p_m, target_.key_m) > opt_.reached_radius_m &&
        std::none_of(approached_.begin(), approached_.end(),
                     [&](const Eigen::Vector3d& a) { return near(a, target_.key_m, 0.5); })) {
      // Stood at its viewpoint and the frontier is still one: walk onto it once.
      approached_.push_back(target_.key_m);
      Goal onto = target_;
      onto.p_m = target_.key_m;
      onto.path_m.clear();
      if (drive(in, onto, r)) {
        adopt(in, onto, r);
        r.reason = "onto the frontier: still one from its viewpoint";
        return true;
      }
    }
    // Stood there and the frontier is still one: nothing more to see from reachable ground.
    add_set_aside(target_.key_m), add_set_aside(target_.p_m);
    ++counts_.stood_at;
    return false;
  }
  if (!still_goal) {
    has_target_ = false;
    return false;
  }
  if (in.t_s > traj_end_s_ + opt_.overdue_s) {  // never arrived: blocked on the way
    add_set_aside(target_.key_m);
    ++counts_.overdue;
    has_target_ = false;
    return false;
  }
  if (in.t_s - planned_at_s_ >= opt_.replan_period_s) {
    has_target_ = false;
    return false;
  }
  // The map has grown since the trajectory was planned (a wall seen late, at a corner): re-check
  // what is left of it, on the plan-time check's sample grid as the local layer does, and replan
  // at once if it now collides rather than follow it until the periodic replan.
  const double t_from = std::clamp(followed_s(in), traj_.t_start(), traj_.t_end());
  if (!traj_.empty() && checker_
                            .check_on_grid(
                                *in.view, [&](double t) { return traj_.pose(t); }, traj_.t_start(),
                                traj_.t_end(), t_from, traj_.t_end() - t_from)
                            .collides) {
    has_target_ = false;
    return false;
  }
  r.status = plan::ExplorationStatus::kKeep;
  r.reason = "keep target";
  r.target_m = target_.p_m;
  r.target_yaw_rad = target_.yaw_rad;
  return true;
}

double GoalDriver::followed_s(const plan::ExplorationInput& in) {
  return in.t_s - std::clamp(in.trajectory_lag_s, 0.0, plan::LocalPlanner::kMaxReferenceLagS);
}

bool GoalDriver::drive(const plan::ExplorationInput& in, const Goal& g,
                       plan::ExplorationResult& r) {
  last_hit_m_ = Eigen::Vector3f::Constant(NAN);
  // The body box with its margin may overlap an obstacle where the robot stands (tracking error,
  // a jamb seen late): every trajectory from there collides at its first pose. As the local
  // layer does, start from the nearest collision-free pose within 0.3 m instead (the control task
  // tracks from the point of a new trajectory nearest the robot).
  const auto free_start = plan::nearest_free_foot(
      checker_, *in.view, plan::BodyPose{in.robot_foot_m, in.robot_yaw_rad, 0.0, in.t_s}, 0.3);
  if (!free_start) return false;
  Eigen::Vector3d start = *free_start;
  double start_yaw = in.robot_yaw_rad;
  // As the local layer does (plan.brake_start): a moving robot's new trajectory starts where it
  // comes to rest, braking along the trajectory it follows (the control task brakes on it before
  // it enters a new one), else straight. From its foot at rest, the body overshot the new
  // trajectory's start by up to 0.4 m and swung into maze walls (maze seed 1, nearest-frontier,
  // straight; maze seed 2, tare-like, braking round a curve into a doorway).
  if (start == in.robot_foot_m) {
    const plan::RestOnTrajectory on =
        plan::rest_on_trajectory(checker_, *in.view, robot_, traj_, start, in.robot_velocity_mps,
                                 followed_s(in), in.t_s, false);
    if (on.kind == plan::RestOnTrajectory::Kind::kRest) {
      start = on.pose.foot_m;
      start_yaw = on.pose.yaw_rad;
    } else if (on.kind == plan::RestOnTrajectory::Kind::kNotOn) {
      if (const auto rest = plan::straight_rest_point(
              checker_, *in.view, robot_, start, in.robot_yaw_rad, in.robot_velocity_mps, in.t_s))
        start = *rest;
    }
  }
  std::vector<Eigen::Vector3d> path = g.path_m;
  if (path.empty() || start != in.robot_foot_m) {
    plan::VoxelPath vp = astar_.plan(*in.view, start, g.p_m);
    if (vp.status == plan::VoxelAStarStatus::kNoStartSupport)
      // The ground under the robot unseen (inside the LiDAR's blind ring after an escape onto
      // ground seen only as far as a frontier): search from the nearest passable support around
      // it instead. Without this every goal failed there and the robot stood still for 1600 s
      // (office seed 2, nearest-frontier, session 35).
      for (const Eigen::Vector3d& s : passable_supports_near(*in.view, start, 0.6, 4)) {
        vp = astar_.plan(*in.view, s, g.p_m);
        if (vp.status != plan::VoxelAStarStatus::kOk) continue;
        vp.points_m.insert(vp.points_m.begin(), start);
        break;
      }
    if (vp.status == plan::VoxelAStarStatus::kOk && !vp.points_m.empty())
      path = std::move(vp.points_m);
    else if (!g.path_m.empty())
      // The goal's own path (fael-like's grid, nearest-frontier's search from the robot), from
      // its point nearest the rest start. The voxel A* judges passability by its own rule: a
      // fael-like viewpoint between classroom desks, free on the plane, was "not passable"
      // from every braking start, 18 goals were set aside so and the run ended "complete" at
      // 244 s with 10 % seen (teaching building seed 4, session 42).
      path = path_from_nearest(g.path_m, start);
    else if (fallback_)
      path = fallback_(in, g);
    else
      path.clear();
    if (path.empty()) return false;
  }
  path.front() = start;
  if (filter_ && !filter_(path)) return false;
  plan::centre_path(*in.view, path);
  plan::align_before_climbs(*in.view, path);
  plan::TrajectoryResult tr =
      builder_.build(*in.view, checker_, path, start_yaw, g.yaw_rad, in.t_s);
  auto failed = [&]() {
    if (tr.hit.collides) last_hit_m_ = tr.hit.voxel_m.cast<float>();
    return tr.status != plan::TrajectoryStatus::kOk &&
           tr.status != plan::TrajectoryStatus::kPolyline;
  };
  // As the local layer does (plan.arrive_along_path): the body hit something within a body length
  // of the goal, turning to its heading: arrive facing along the path. tare-like's goals at the
  // foot of the maze's 1.5 m wide ramp faced its side and were set aside, and the run ended
  // "complete" below the ramp (maze seed 4, session 37).
  double goal_yaw = g.yaw_rad;
  if (failed()) {
    if (!arrive_along_path_ || !tr.hit.collides ||
        (tr.hit.voxel_m - g.p_m).head<2>().norm() > robot_.body_length_m)
      return false;
    tr = builder_.build(*in.view, checker_, path, start_yaw, std::nullopt, in.t_s);
    if (failed()) return false;
    goal_yaw = tr.trajectory.pose(tr.trajectory.t_end()).yaw_rad;
  }
  r.status = plan::ExplorationStatus::kNewTrajectory;
  r.trajectory = std::move(tr.trajectory);
  r.real_until_s = r.trajectory.t_end();  // baselines have no hypothetical space
  r.target_m = g.p_m;
  r.target_yaw_rad = goal_yaw;
  return true;
}

std::vector<Eigen::Vector3d> GoalDriver::path_from_nearest(const std::vector<Eigen::Vector3d>& path,
                                                           const Eigen::Vector3d& start) {
  std::vector<Eigen::Vector3d> out{start};
  if (path.empty()) return out;
  size_t k = 0;
  for (size_t i = 1; i < path.size(); ++i)
    if (dist_xy(path[i], start) < dist_xy(path[k], start)) k = i;
  out.insert(out.end(), path.begin() + std::ptrdiff_t(k) + 1, path.end());
  if (out.size() < 2) out.push_back(path.back());
  return out;
}

std::vector<Eigen::Vector3d> GoalDriver::passable_supports_near(const map::MapView& view,
                                                                const Eigen::Vector3d& p_m,
                                                                double radius_m,
                                                                size_t max_n) const {
  std::vector<std::pair<double, Eigen::Vector3d>> found;
  const double step = view.voxel_size_m();
  const int n = int(std::ceil(radius_m / step));
  for (int dx = -n; dx <= n; ++dx)
    for (int dy = -n; dy <= n; ++dy) {
      const double d = step * std::hypot(dx, dy);
      if (d > radius_m) continue;
      const Eigen::Vector3d q = p_m + Eigen::Vector3d(dx * step, dy * step, 0);
      const auto s = view.support_surface_near(q.cast<float>(), 0.3);
      if (!s || !astar_.passable(view, s->key, s->height_m)) continue;
      found.push_back({d, Eigen::Vector3d(q.x(), q.y(), s->height_m)});
    }
  std::stable_sort(found.begin(), found.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3d> out;
  // Spread out: a candidate within 0.25 m of one already taken adds little.
  for (const auto& [d, q] : found) {
    if (out.size() >= max_n) break;
    if (std::any_of(out.begin(), out.end(),
                    [&](const Eigen::Vector3d& o) { return (o - q).head<2>().norm() < 0.25; }))
      continue;
    out.push_back(q);
  }
  return out;
}

bool GoalDriver::escape_away_from(const plan::ExplorationInput& in, const Eigen::Vector3f& hit,
                                  const char* reason, plan::ExplorationResult& r) {
  const Eigen::Vector3d start =
      plan::nearest_free_foot(checker_, *in.view,
                              plan::BodyPose{in.robot_foot_m, in.robot_yaw_rad, 0.0, in.t_s}, 0.3)
          .value_or(in.robot_foot_m);
  auto w = plan::escape_to_turn(checker_, *in.view, robot_, start, in.robot_yaw_rad, in.t_s,
                                opt_.escape_turn_radius_m, &hit);
  if (!w) return false;
  publish_escape(std::move(*w), in, r);
  r.reason = reason;
  return true;
}

void GoalDriver::publish_escape(plan::StraightWalk w, const plan::ExplorationInput& in,
                                plan::ExplorationResult& r) {
  has_target_ = false;
  ever_moved_ = true;
  escaping_ = true;
  escape_end_s_ = w.trajectory.t_end();
  escape_to_m_ = w.to_m;
  traj_ = w.trajectory;  // followed now (a later start brakes along it)
  r.status = plan::ExplorationStatus::kNewTrajectory;
  r.trajectory = std::move(w.trajectory);
  r.real_until_s = r.trajectory.t_end();
  r.target_m = w.to_m;
  r.target_yaw_rad = in.robot_yaw_rad;
}

void GoalDriver::adopt(const plan::ExplorationInput& in, const Goal& g,
                       const plan::ExplorationResult& r) {
  ever_moved_ = true;
  has_target_ = true;
  target_ = g;
  target_.yaw_rad = r.target_yaw_rad;  // facing along the path where the goal heading collided
  planned_at_s_ = in.t_s;
  traj_end_s_ = r.trajectory.t_end();
  traj_ = r.trajectory;
}

void GoalDriver::choose(const plan::ExplorationInput& in, std::vector<Goal>& goals,
                        plan::ExplorationResult& r) {
  std::erase_if(goals, [&](const Goal& g) { return set_aside(g); });
  if (goals.empty()) {
    // Nothing to see yet because the reachable set has not reached the robot (start-up): the
    // map is still growing, not exhausted. Only before the first trajectory: later, a robot
    // stranded off the reachable set waited here for ever (house seed 3, nearest-frontier: 1773 s
    // standing where it could neither turn nor escape).
    const auto s = in.view->support_surface_near(in.robot_foot_m.cast<float>(), 0.3);
    if (!ever_moved_ && (!s || !s->reachable)) {
      r.status = plan::ExplorationStatus::kExploring;
      r.reason = "no reachable support at the robot yet";
      return;
    }
    r.status = plan::ExplorationStatus::kComplete;
    r.reason = "no reachable, observable frontier left";
    return;
  }
  std::stable_sort(goals.begin(), goals.end(),
                   [](const Goal& a, const Goal& b) { return a.cost < b.cost; });
  int attempts = 0;
  std::vector<const Goal*> failed;
  // As the local layer does: every attempt's body hit an obstacle next to the start (the robot
  // stands by a wall end it cannot curve away from), so the start is to blame, not the goals.
  // Counted against the goals, every goal of the maze was set aside from one such spot and the
  // run ended "complete" at 782.5 s below the ramp (maze seed 1, tare-like, session 37).
  bool boxed_in = true;
  Eigen::Vector3f hit = Eigen::Vector3f::Constant(NAN);  // the hit nearest the start
  double hit_d = std::numeric_limits<double>::infinity();
  for (const Goal& g : goals) {
    if (attempts++ >= opt_.max_attempts) break;
    if (drive(in, g, r)) {
      adopt(in, g, r);
      start_escapes_ = 0;
      r.reason = "new frontier target";
      return;
    }
    failed.push_back(&g);
    const double d = last_hit_m_.allFinite() ? dist_xy(last_hit_m_.cast<double>(), in.robot_foot_m)
                                             : std::numeric_limits<double>::infinity();
    boxed_in = boxed_in && d <= opt_.start_blame_radius_m;
    if (d < hit_d) hit_d = d, hit = last_hit_m_;
  }
  // As the local layer does: where the body cannot turn on the spot (a corridor narrower than
  // its turning circle) every path starting with a turn fails, whatever the goal; step straight
  // to the nearest place where it can turn and try again from there (the goals are not blamed).
  if (!failed.empty() && !plan::can_turn_at(checker_, *in.view, in.robot_foot_m, in.robot_yaw_rad))
    if (auto w = plan::escape_to_turn(checker_, *in.view, robot_, in.robot_foot_m, in.robot_yaw_rad,
                                      in.t_s, opt_.escape_turn_radius_m)) {
      publish_escape(std::move(*w), in, r);
      r.reason = "escape: cannot turn here";
      return;
    }
  if (!failed.empty() && boxed_in && start_escapes_ < opt_.max_start_escapes &&
      escape_away_from(in, hit, "escape: boxed in by an obstacle next to the start", r)) {
    ++start_escapes_;
    return;
  }
  for (const Goal* gp : failed) {
    const Goal& g = *gp;
    auto it = std::find_if(failures_.begin(), failures_.end(),
                           [&](const auto& f) { return near(f.first, g.key_m, 0.3); });
    if (it == failures_.end()) it = failures_.insert(failures_.end(), {g.key_m, 0});
    if (++it->second >= opt_.max_failures) {
      add_set_aside(g.key_m);
      add_set_aside(g.p_m);
      ++counts_.no_trajectory;
      failures_.erase(it);
    }
  }
  has_target_ = false;
  r.status = plan::ExplorationStatus::kExploring;
  r.reason = "no feasible trajectory to a frontier this cycle";
}

}  // namespace storey::core::baselines
