#include "tracking/pose_evaluator/sequence_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::evaluation {
namespace {

double angle_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  double dot = std::clamp(std::abs(qa.normalized().dot(qb.normalized())), 0.0, 1.0);
  return 2 * std::acos(dot) * 180 / M_PI;
}

double percent(int part, int whole) {
  return whole == 0 ? std::numeric_limits<double>::quiet_NaN() : 100.0 * part / whole;
}

}  // namespace

std::optional<std::string> SequenceOptions::problem() const {
  if (!(position_bound_m > 0)) {
    return fmt::format("position_bound_m: {} is not above 0", position_bound_m);
  }
  if (!(orientation_bound_deg > 0)) {
    return fmt::format("orientation_bound_deg: {} is not above 0", orientation_bound_deg);
  }
  return std::nullopt;
}

SequenceEvaluator::SequenceEvaluator(SequenceOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("SequenceOptions::" + *problem);
  }
}

double SequenceScore::acquired_percent() const { return percent(acquired, episodes); }
double SequenceScore::tracked_after_acquisition_percent() const {
  return percent(tracked_after_acquisition, frames_after_acquisition);
}
double SequenceScore::tracked_percent() const { return percent(tracked_frames, trackable_frames); }

bool SequenceEvaluator::trackable(const SequenceTruth& truth) {
  return truth.facing_camera && truth.pose.translation().z() > 0 && truth.visible_markers >= 4 &&
         2 * truth.visible_markers >= truth.markers;
}

void SequenceEvaluator::add_frame(double time_s, const std::vector<SequenceTruth>& truth,
                                  const std::vector<SequenceEstimate>& estimates) {
  auto near = [&](const SequenceEstimate& estimate, const SequenceTruth& object) {
    return (estimate.pose.translation() - object.pose.translation()).norm() <=
               options_.position_bound_m &&
           angle_deg(estimate.pose, object.pose) <= options_.orientation_bound_deg;
  };
  std::vector<bool> right(estimates.size(), false);
  for (size_t e = 0; e < estimates.size(); ++e) {
    const SequenceEstimate& estimate = estimates[e];
    bool swap = false;
    for (const SequenceTruth& object : truth) {
      if (!near(estimate, object)) continue;
      if (object.name == estimate.name) {
        right[e] = true;
      } else {
        swap = true;
      }
    }
    if (right[e]) continue;
    if (swap) {
      ++score_.identity_swaps;
    } else {
      ++score_.false_identifications;
    }
  }
  for (const SequenceTruth& object : truth) {
    if (!trackable(object)) {
      open_.erase(object.name);
      continue;
    }
    auto [episode, started] = open_.try_emplace(object.name);
    if (started) {
      episode->second.start_s = time_s;
      ++score_.episodes;
    }
    ++score_.trackable_frames;
    const SequenceEstimate* found = nullptr;
    for (size_t e = 0; e < estimates.size(); ++e) {
      if (right[e] && estimates[e].name == object.name) found = &estimates[e];
    }
    if (found && !episode->second.acquired) {
      episode->second.acquired = true;
      ++score_.acquired;
      score_.acquisition_delay_s.push_back(time_s - episode->second.start_s);
    }
    if (episode->second.acquired) {
      ++score_.frames_after_acquisition;
      score_.tracked_after_acquisition += found != nullptr;
    }
    if (!found) continue;
    ++score_.tracked_frames;
    score_.position_error_mm.push_back(
        (found->pose.translation() - object.pose.translation()).norm() * 1e3);
    score_.orientation_error_deg.push_back(angle_deg(found->pose, object.pose));
    if (found->linear_velocity && found->angular_velocity) {
      score_.velocity_error_mps.push_back(
          (*found->linear_velocity - object.linear_velocity).norm());
      score_.angular_velocity_error_dps.push_back(
          (*found->angular_velocity - object.angular_velocity).norm() * 180 / M_PI);
    }
  }
  // Boards no longer in the truth (behind the camera) end their episodes.
  for (auto it = open_.begin(); it != open_.end();) {
    bool present = std::any_of(truth.begin(), truth.end(),
                               [&](const SequenceTruth& t) { return t.name == it->first; });
    it = present ? std::next(it) : open_.erase(it);
  }
}

}  // namespace mocap::evaluation
