#include "tracking/pose_evaluator/pose_evaluator.hpp"

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
  return 2 * std::acos(dot) * 180 / M_PI;  // seed eq. 10
}

void merge(EvaluationSummary& into, const EvaluationSummary& from) {
  into.frames += from.frames;
  into.frames_lost += from.frames_lost;
  into.expected += from.expected;
  into.tracked += from.tracked;
  into.incomplete_frames += from.incomplete_frames;
  into.expected_in_incomplete += from.expected_in_incomplete;
  into.tracked_in_incomplete += from.tracked_in_incomplete;
  into.false_identifications += from.false_identifications;
  into.identity_swaps += from.identity_swaps;
  into.objects = std::max(into.objects, from.objects);
  into.false_identification_details.insert(into.false_identification_details.end(),
                                           from.false_identification_details.begin(),
                                           from.false_identification_details.end());
  into.position_errors_m.insert(into.position_errors_m.end(), from.position_errors_m.begin(),
                                from.position_errors_m.end());
  into.orientation_errors_deg.insert(into.orientation_errors_deg.end(),
                                     from.orientation_errors_deg.begin(),
                                     from.orientation_errors_deg.end());
  into.velocity_errors_mps.insert(into.velocity_errors_mps.end(), from.velocity_errors_mps.begin(),
                                  from.velocity_errors_mps.end());
  into.angular_velocity_errors_dps.insert(into.angular_velocity_errors_dps.end(),
                                          from.angular_velocity_errors_dps.begin(),
                                          from.angular_velocity_errors_dps.end());
}

}  // namespace

std::optional<std::string> EvaluationOptions::problem() const {
  if (min_visible_markers < 0) {
    return fmt::format("min_visible_markers: {} is below 0", min_visible_markers);
  }
  if (!(false_position_error_m > 0)) {
    return fmt::format("false_position_error_m: {} is not above 0", false_position_error_m);
  }
  if (!(false_orientation_error_deg > 0)) {
    return fmt::format("false_orientation_error_deg: {} is not above 0",
                       false_orientation_error_deg);
  }
  // With none pending, a truth frame and its estimate could never meet.
  if (max_pending_frames == 0) {
    return "max_pending_frames: 0; a frame's truth and estimate could never meet";
  }
  return std::nullopt;
}

PoseEvaluator::PoseEvaluator(EvaluationOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("EvaluationOptions::" + *problem);
  }
}

double EvaluationSummary::tracked_percent() const {
  return expected == 0 ? std::numeric_limits<double>::quiet_NaN() : 100.0 * tracked / expected;
}

double EvaluationSummary::tracked_percent_in_complete_frames() const {
  const uint64_t complete_expected = expected - expected_in_incomplete;
  return complete_expected == 0 ? std::numeric_limits<double>::quiet_NaN()
                                : 100.0 * static_cast<double>(tracked - tracked_in_incomplete) /
                                      static_cast<double>(complete_expected);
}

double EvaluationSummary::quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  size_t index = std::min(values.size() - 1, static_cast<size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(index), values.end());
  return values[index];
}

void PoseEvaluator::add_truth(int64_t stamp_ns, std::vector<ObjectPose> objects) {
  if (auto estimate = pending_estimates_.find(stamp_ns); estimate != pending_estimates_.end()) {
    evaluate(stamp_ns, objects, estimate->second);
    pending_estimates_.erase(estimate);
    return;
  }
  pending_truth_[stamp_ns] = std::move(objects);
  expire();
}

void PoseEvaluator::add_estimate(int64_t stamp_ns, std::vector<ObjectPose> objects,
                                 bool incomplete) {
  Estimate estimate{std::move(objects), incomplete};
  if (auto truth = pending_truth_.find(stamp_ns); truth != pending_truth_.end()) {
    evaluate(stamp_ns, truth->second, estimate);
    pending_truth_.erase(truth);
    return;
  }
  pending_estimates_[stamp_ns] = std::move(estimate);
  expire();
}

void PoseEvaluator::evaluate(int64_t stamp_ns, const std::vector<ObjectPose>& truth,
                             const Estimate& estimate) {
  EvaluationSummary frame;
  auto count_false = [&](const std::string& name, double position, double orientation) {
    ++frame.false_identifications;
    frame.false_identification_details.push_back({stamp_ns, name, position, orientation});
  };
  frame.frames = 1;
  frame.objects = truth.size();
  for (const ObjectPose& t : truth) {
    if (t.visible_markers >= options_.min_visible_markers) ++frame.expected;
  }
  for (const ObjectPose& e : estimate.objects) {
    auto t = std::find_if(truth.begin(), truth.end(),
                          [&](const ObjectPose& o) { return o.name == e.name; });
    if (t == truth.end()) {
      count_false(e.name, std::numeric_limits<double>::quiet_NaN(),
                  std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    double position = (e.pose.translation() - t->pose.translation()).norm();
    double orientation = e.orientation_known ? angle_deg(e.pose, t->pose) : 0;
    if (std::any_of(truth.begin(), truth.end(), [&](const ObjectPose& other) {
          return &other != &*t &&
                 (e.pose.translation() - other.pose.translation()).norm() < position;
        })) {
      ++frame.identity_swaps;
    }
    if (position > options_.false_position_error_m ||
        orientation > options_.false_orientation_error_deg) {
      count_false(e.name, position, orientation);
      continue;
    }
    // Found with fewer visible markers than expected is a bonus, not a trackable object.
    if (t->visible_markers >= options_.min_visible_markers) ++frame.tracked;
    frame.position_errors_m.push_back(position);
    if (e.orientation_known) frame.orientation_errors_deg.push_back(orientation);
    if (e.linear_velocity && t->linear_velocity) {
      frame.velocity_errors_mps.push_back((*e.linear_velocity - *t->linear_velocity).norm());
    }
    if (e.angular_velocity && t->angular_velocity) {
      frame.angular_velocity_errors_dps.push_back(
          (*e.angular_velocity - *t->angular_velocity).norm() * 180 / M_PI);
    }
  }
  if (estimate.incomplete) {
    frame.incomplete_frames = 1;
    frame.expected_in_incomplete = frame.expected;
    frame.tracked_in_incomplete = frame.tracked;
  }
  merge(total_, frame);
  merge(window_, frame);
}

void PoseEvaluator::expire() {
  // Truth without estimates: the pipeline dropped the frame. Estimates without truth: the
  // truth was lost (it is reliable, so only at start-up); they are not judged.
  while (pending_truth_.size() > options_.max_pending_frames) {
    EvaluationSummary lost;
    lost.frames = 1;
    lost.frames_lost = 1;
    for (const ObjectPose& t : pending_truth_.begin()->second) {
      if (t.visible_markers >= options_.min_visible_markers) ++lost.expected;
    }
    merge(total_, lost);
    merge(window_, lost);
    pending_truth_.erase(pending_truth_.begin());
  }
  while (pending_estimates_.size() > options_.max_pending_frames) {
    pending_estimates_.erase(pending_estimates_.begin());
  }
}

EvaluationSummary PoseEvaluator::take_window() {
  EvaluationSummary window = std::move(window_);
  window_ = {};
  return window;
}

}  // namespace mocap::evaluation
