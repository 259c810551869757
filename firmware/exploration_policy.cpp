#include "firmware/exploration_policy.hpp"

#include <stdexcept>

#include "core/baselines/fael_like_planner.hpp"
#include "core/baselines/nearest_frontier_planner.hpp"
#include "core/baselines/tare_like_planner.hpp"

namespace storey::firmware {

namespace {

// The paper's method: the macro layer over the local layer (exploration_planner.hpp).
class StoreyPolicy final : public ExplorationPolicy {
 public:
  explicit StoreyPolicy(const config::Parameters& p)
      : planner_(p.robot, p.plan, p.map.voxel_size_m) {}
  const char* name() const override { return "storey"; }
  core::plan::ExplorationResult plan(const core::plan::ExplorationInput& in) override {
    return planner_.plan(in);
  }
  void drop_target() override { planner_.drop_target(); }
  const core::plan::LocalPlanner* local_layer() const override {
    return &const_cast<core::plan::ExplorationPlanner&>(planner_).local();
  }
  const core::plan::ExplorationPlanner* macro_layer() const override { return &planner_; }

 private:
  core::plan::ExplorationPlanner planner_;
};

// A baseline of core/baselines/ (same input, same result shape).
template <class Planner>
class BaselinePolicy final : public ExplorationPolicy {
 public:
  BaselinePolicy(const char* name, const config::Parameters& p)
      : name_(name), planner_(p.robot, p.plan, p.map.voxel_size_m) {}
  const char* name() const override { return name_; }
  core::plan::ExplorationResult plan(const core::plan::ExplorationInput& in) override {
    return planner_.plan(in);
  }
  void drop_target() override { planner_.drop_target(); }
  const core::baselines::GoalDriver::SetAsideCounts* goals_set_aside() const override {
    return &planner_.driver().set_aside_counts();
  }

 private:
  const char* name_;
  Planner planner_;
};

}  // namespace

const std::vector<std::string>& exploration_methods() {
  static const std::vector<std::string> m = {"storey", "nearest-frontier", "fael-like",
                                             "tare-like"};
  return m;
}

std::unique_ptr<ExplorationPolicy> make_exploration_policy(const std::string& method,
                                                           const config::Parameters& params) {
  namespace b = core::baselines;
  if (method == "storey") return std::make_unique<StoreyPolicy>(params);
  if (method == "nearest-frontier")
    return std::make_unique<BaselinePolicy<b::NearestFrontierPlanner>>("nearest-frontier", params);
  if (method == "fael-like")
    return std::make_unique<BaselinePolicy<b::FaelLikePlanner>>("fael-like", params);
  if (method == "tare-like")
    return std::make_unique<BaselinePolicy<b::TareLikePlanner>>("tare-like", params);
  throw std::invalid_argument("exploration method '" + method +
                              "': unknown (known: storey, nearest-frontier, fael-like, tare-like)");
}

}  // namespace storey::firmware
