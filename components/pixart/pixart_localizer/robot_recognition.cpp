#include "pixart/pixart_localizer/robot_recognition.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::pixart::localization {
namespace {

const std::tuple<size_t, size_t, size_t> kPermutations[] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                                            {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

// Why `value` cannot be a distance that must be positive: not above 0, or infinite.
std::optional<std::string> not_positive(const char* name, double value) {
  if (!(value > 0)) return fmt::format("{}: {} is not above 0", name, value);
  if (!std::isfinite(value)) return fmt::format("{}: {} is not finite", name, value);
  return std::nullopt;
}

std::optional<std::string> layout_problem(const RobotModel& robot, double tolerance) {
  if (robot.leds.size() != 3) {
    return fmt::format("has {} LEDs; the recognizer needs the seed's 3", robot.leds.size());
  }
  int steady = 0;
  for (const Led& led : robot.leds) steady += led.off_s <= 0 ? 1 : 0;
  if (steady != 1) {
    return fmt::format("has {} always-on LEDs; the recognizer needs exactly 1", steady);
  }
  double d01 = (robot.leds[0].position - robot.leds[1].position).norm();
  double d02 = (robot.leds[0].position - robot.leds[2].position).norm();
  double d12 = (robot.leds[1].position - robot.leds[2].position).norm();
  double closest = std::min({std::abs(d01 - d02), std::abs(d01 - d12), std::abs(d02 - d12)});
  if (closest <= 2 * tolerance) {
    return fmt::format(
        "has LED distances {:.3f}, {:.3f}, {:.3f} m, two of them within twice the pattern "
        "tolerance ({} m) of each other: its LEDs could not be told apart",
        d01, d02, d12, tolerance);
  }
  return std::nullopt;
}

// Whether one camera saw all of `points` (with no camera sets given, one camera saw all).
bool seen_by_one_camera(const std::vector<CameraSet>& cameras,
                        std::initializer_list<size_t> points) {
  if (cameras.empty()) return true;
  CameraSet common = ~CameraSet{0};
  for (size_t p : points) common &= cameras[p];
  return common != 0;
}

}  // namespace

const char* to_string(PoseEvidence evidence) {
  switch (evidence) {
    case PoseEvidence::AllLeds:
      return "3 LEDs";
    case PoseEvidence::TwoLeds:
      return "2 LEDs";
    case PoseEvidence::OneLed:
      return "one LED";
  }
  return "?";
}

std::optional<std::string> RecognitionOptions::problem() const {
  if (auto problem = not_positive("pattern_tolerance_m", pattern_tolerance_m)) return problem;
  if (auto problem = not_positive("tracking_gate_m", tracking_gate_m)) return problem;
  return std::nullopt;
}

RobotRecognizer::RobotRecognizer(const std::vector<RobotModel>& robots, RecognitionOptions options)
    : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("RecognitionOptions::" + *problem);
  }
  for (const RobotModel& robot : robots) {
    if (auto problem = layout_problem(robot, options_.pattern_tolerance_m)) {
      unsupported_.push_back(fmt::format("robot '{}': {}", robot.name, *problem));
      patterns_.emplace_back();
      continue;
    }
    Pattern pattern;
    for (size_t i = 0; i < 3; ++i) {
      pattern.leds[i] = robot.leds[i].position;
      if (robot.leds[i].off_s <= 0) pattern.steady = i;
    }
    for (size_t a = 0; a < 3; ++a) {
      for (size_t b = 0; b < 3; ++b) {
        pattern.distance[a][b] = (pattern.leds[a] - pattern.leds[b]).norm();
      }
    }
    patterns_.push_back(pattern);
  }
  // A steady-to-end spacing identifies its robot when no other LED distance of any robot
  // (its own included) is within twice the tolerance: a measured distance within the
  // tolerance of it then fits nothing else.
  for (size_t r = 0; r < patterns_.size(); ++r) {
    if (!patterns_[r]) continue;
    Pattern& pattern = *patterns_[r];
    for (size_t end = 0; end < 3; ++end) {
      if (end == pattern.steady) continue;
      double spacing = pattern.distance[pattern.steady][end];
      bool unique = true;
      for (size_t q = 0; q < patterns_.size(); ++q) {
        if (!patterns_[q]) continue;
        for (size_t a = 0; a < 3; ++a) {
          for (size_t b = a + 1; b < 3; ++b) {
            bool itself =
                q == r && ((a == pattern.steady && b == end) || (b == pattern.steady && a == end));
            if (!itself && std::abs(patterns_[q]->distance[a][b] - spacing) <=
                               2 * options_.pattern_tolerance_m) {
              unique = false;
            }
          }
        }
      }
      pattern.identifying_spacing[end] = unique;
    }
  }
}

double RobotRecognizer::smallest_led_distance_m() const {
  double smallest = std::numeric_limits<double>::infinity();
  for (const auto& pattern : patterns_) {
    if (!pattern) continue;
    smallest = std::min(
        {smallest, pattern->distance[0][1], pattern->distance[0][2], pattern->distance[1][2]});
  }
  return std::isfinite(smallest) ? smallest : 0.0;
}

RecognitionResult RobotRecognizer::recognize(const std::vector<Eigen::Vector2d>& points,
                                             const std::vector<std::optional<PlanarPose>>& tracked,
                                             const std::vector<CameraSet>& cameras) const {
  if (!cameras.empty() && cameras.size() != points.size()) {
    throw std::invalid_argument(
        fmt::format("{} camera sets for {} points", cameras.size(), points.size()));
  }
  RecognitionResult result;
  std::vector<bool> used(points.size(), false);
  std::vector<bool> found(patterns_.size(), false);
  // Untracked robots, whatever the caller's vector holds.
  std::vector<std::optional<PlanarPose>> priors(patterns_.size());
  for (size_t r = 0; r < priors.size() && r < tracked.size(); ++r) priors[r] = tracked[r];

  find_triples(points, cameras, used, found, result);
  find_pairs(points, priors, cameras, used, found, result);
  find_single_leds(points, priors, used, found, result);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!used[i]) result.unexplained_points.push_back(i);
  }
  return result;
}

void RobotRecognizer::find_triples(const std::vector<Eigen::Vector2d>& points,
                                   const std::vector<CameraSet>& cameras, std::vector<bool>& used,
                                   std::vector<bool>& found, RecognitionResult& result) const {
  const double tolerance = options_.pattern_tolerance_m;
  struct Candidate {
    Recognition recognition;
    bool one_camera;
  };
  std::vector<Candidate> candidates;
  const size_t n = points.size();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      double dij = (points[i] - points[j]).norm();
      for (size_t k = j + 1; k < n; ++k) {
        double dik = (points[i] - points[k]).norm(), djk = (points[j] - points[k]).norm();
        for (size_t r = 0; r < patterns_.size(); ++r) {
          if (!patterns_[r]) continue;
          const Pattern& pattern = *patterns_[r];
          // Point i shows LED a, j shows b, k shows c.
          for (const auto& [a, b, c] : kPermutations) {
            if (std::abs(dij - pattern.distance[a][b]) > tolerance ||
                std::abs(dik - pattern.distance[a][c]) > tolerance ||
                std::abs(djk - pattern.distance[b][c]) > tolerance) {
              continue;
            }
            PlanarFit fit = fit_planar_pose({pattern.leds[a], pattern.leds[b], pattern.leds[c]},
                                            {points[i], points[j], points[k]});
            if (fit.max_residual_m > tolerance) continue;  // the mirror image of the layout
            candidates.push_back(
                {{r, fit.pose, PoseEvidence::AllLeds, {i, j, k}, fit.rms_residual_m},
                 seen_by_one_camera(cameras, {i, j, k})});
          }
        }
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& l, const Candidate& r) {
    if (l.one_camera != r.one_camera) return l.one_camera;
    return l.recognition.rms_residual_m < r.recognition.rms_residual_m;
  });
  for (Candidate& candidate : candidates) {
    Recognition& recognition = candidate.recognition;
    if (found[recognition.robot]) continue;
    if (std::any_of(recognition.points.begin(), recognition.points.end(),
                    [&](size_t p) { return used[p]; })) {
      continue;
    }
    found[recognition.robot] = true;
    for (size_t p : recognition.points) used[p] = true;
    result.robots.push_back(std::move(recognition));
  }
}

void RobotRecognizer::find_pairs(const std::vector<Eigen::Vector2d>& points,
                                 const std::vector<std::optional<PlanarPose>>& tracked,
                                 const std::vector<CameraSet>& cameras, std::vector<bool>& used,
                                 std::vector<bool>& found, RecognitionResult& result) const {
  const double tolerance = options_.pattern_tolerance_m;
  struct Candidate {
    Recognition recognition;
    bool one_camera;
    double distance_to_track;  // of both LEDs, summed: the nearest are taken first
  };
  std::vector<Candidate> candidates;
  const size_t n = points.size();
  for (size_t i = 0; i < n; ++i) {
    if (used[i]) continue;
    for (size_t j = i + 1; j < n; ++j) {
      if (used[j]) continue;
      double d = (points[i] - points[j]).norm();
      bool fits_any = false;
      std::optional<std::pair<size_t, size_t>> identified;  // robot, end LED
      for (size_t r = 0; r < patterns_.size(); ++r) {
        if (!patterns_[r]) continue;
        const Pattern& pattern = *patterns_[r];
        for (size_t a = 0; a < 3; ++a) {
          for (size_t b = a + 1; b < 3; ++b) {
            if (std::abs(d - pattern.distance[a][b]) > tolerance) continue;
            fits_any = true;
            size_t end = a == pattern.steady ? b : b == pattern.steady ? a : 3;
            if (end < 3 && pattern.identifying_spacing[end]) identified = {{r, end}};
          }
        }
      }
      if (!identified) {
        if (fits_any) ++result.ambiguous_pairs;
        continue;
      }
      auto [r, end] = *identified;
      if (found[r] || !tracked[r]) continue;
      const Pattern& pattern = *patterns_[r];
      const Eigen::Vector2d expected_steady = tracked[r]->to_world(pattern.leds[pattern.steady]);
      const Eigen::Vector2d expected_end = tracked[r]->to_world(pattern.leds[end]);
      // Both LEDs, not the steady one alone: a camera off by half the spacing puts the end LED
      // as near the tracked steady LED as the steady one.
      const double i_steady =
                       (points[i] - expected_steady).norm() + (points[j] - expected_end).norm(),
                   j_steady =
                       (points[j] - expected_steady).norm() + (points[i] - expected_end).norm();
      const size_t steady_point = i_steady <= j_steady ? i : j;
      const size_t end_point = steady_point == i ? j : i;
      if ((points[steady_point] - expected_steady).norm() > options_.tracking_gate_m) continue;
      const double distance_to_track = std::min(i_steady, j_steady);
      PlanarFit fit = fit_planar_pose({pattern.leds[pattern.steady], pattern.leds[end]},
                                      {points[steady_point], points[end_point]});
      candidates.push_back(
          {{r, fit.pose, PoseEvidence::TwoLeds, {steady_point, end_point}, fit.rms_residual_m},
           seen_by_one_camera(cameras, {i, j}),
           distance_to_track});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& l, const Candidate& r) {
    if (l.one_camera != r.one_camera) return l.one_camera;
    return l.distance_to_track < r.distance_to_track;
  });
  for (Candidate& candidate : candidates) {
    Recognition& recognition = candidate.recognition;
    if (found[recognition.robot] || used[recognition.points[0]] || used[recognition.points[1]]) {
      continue;
    }
    found[recognition.robot] = true;
    for (size_t p : recognition.points) used[p] = true;
    result.robots.push_back(std::move(recognition));
  }
}

void RobotRecognizer::find_single_leds(const std::vector<Eigen::Vector2d>& points,
                                       const std::vector<std::optional<PlanarPose>>& tracked,
                                       std::vector<bool>& used, std::vector<bool>& found,
                                       RecognitionResult& result) const {
  struct Candidate {
    double distance;
    size_t point, robot, led;
  };
  std::vector<Candidate> candidates;
  for (size_t r = 0; r < patterns_.size(); ++r) {
    if (!patterns_[r] || found[r] || !tracked[r]) continue;
    for (size_t led = 0; led < patterns_[r]->leds.size(); ++led) {
      Eigen::Vector2d expected = tracked[r]->to_world(patterns_[r]->leds[led]);
      for (size_t i = 0; i < points.size(); ++i) {
        if (used[i]) continue;
        double distance = (points[i] - expected).norm();
        if (distance <= options_.tracking_gate_m) candidates.push_back({distance, i, r, led});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& l, const Candidate& r) { return l.distance < r.distance; });
  for (const Candidate& candidate : candidates) {
    if (found[candidate.robot] || used[candidate.point]) continue;
    found[candidate.robot] = true;
    used[candidate.point] = true;
    // That LED lands on the point; the heading stays.
    PlanarPose pose = *tracked[candidate.robot];
    const Pattern& pattern = *patterns_[candidate.robot];
    Eigen::Vector2d offset = PlanarPose{0, 0, pose.theta}.to_world(pattern.leds[candidate.led]);
    pose.x = points[candidate.point].x() - offset.x();
    pose.y = points[candidate.point].y() - offset.y();
    result.robots.push_back({candidate.robot, pose, PoseEvidence::OneLed, {candidate.point}, 0});
  }
}

}  // namespace mocap::pixart::localization
