#include "pixart/pixart_localizer/pixart_localizer.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace mocap::pixart::localization {
namespace {

std::vector<std::string> robot_names(const Rig& rig) {
  std::vector<std::string> names;
  for (const RobotModel& robot : rig.robots) names.push_back(robot.name);
  return names;
}

// The options, once they are known to be usable: the recognizer and the tracker are built
// from them.
const LocalizerOptions& checked(const LocalizerOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("LocalizerOptions::" + *problem);
  }
  return options;
}

}  // namespace

std::optional<std::string> LocalizerOptions::problem() const {
  if (auto problem = merging.problem()) return "merging." + *problem;
  if (auto problem = recognition.problem()) return "recognition." + *problem;
  if (auto problem = tracking.problem()) return "tracking." + *problem;
  return std::nullopt;
}

RobotLocalizer::RobotLocalizer(Rig rig, LocalizerOptions options)
    : rig_(std::move(rig)),
      options_(checked(options)),
      recognizer_(rig_.robots, options_.recognition),
      tracker_(robot_names(rig_), options_.tracking),
      views_(rig_.cameras.size()) {
  if (rig_.cameras.empty() || rig_.cameras.size() > kMaxCameras) {
    throw std::invalid_argument(
        fmt::format("the rig {} has {} cameras; the localizer takes 1 to {}", rig_.source,
                    rig_.cameras.size(), kMaxCameras));
  }
  if (recognizer_.unsupported().size() == rig_.robots.size()) {
    throw std::invalid_argument(fmt::format(
        "none of the robots of the rig {} can be recognised{}{}", rig_.source,
        rig_.robots.empty() ? " (it has none)" : ": ", fmt::join(recognizer_.unsupported(), "; ")));
  }
  double smallest = recognizer_.smallest_led_distance_m();
  if (options_.merging.merge_distance_m >= smallest) {
    throw std::invalid_argument(fmt::format(
        "merge_distance_m ({} m) must be below the smallest distance between two LEDs of a "
        "robot ({:.3f} m), or two LEDs seen by two cameras would become one",
        options_.merging.merge_distance_m, smallest));
  }
}

RobotLocalizer::SampleStatus RobotLocalizer::add_sample(
    std::string_view camera, int64_t stamp_ns, const std::vector<Eigen::Vector2d>& pixels) {
  size_t index = 0;
  while (index < rig_.cameras.size() && rig_.cameras[index].name != camera) ++index;
  if (index == rig_.cameras.size()) {
    ++stats_.unknown_camera_samples;
    return SampleStatus::UnknownCamera;
  }
  LedPlanePoints projected =
      project_to_led_plane(rig_.cameras[index], pixels, rig_.led_plane_height_m);
  stats_.non_finite_pixels += projected.non_finite_pixels;
  stats_.unprojectable_pixels += projected.unprojectable_pixels;
  if (!views_.update(index, stamp_ns, std::move(projected.points))) {
    ++stats_.out_of_order_samples;
    return SampleStatus::OutOfOrder;
  }
  ++stats_.samples;

  last_points_ = merge_views(views_.views(), options_.merging);
  // A robot unread for too long must not be revived by a lone LED near its old place.
  tracker_.expire(last_points_.stamp_ns);
  std::vector<Eigen::Vector2d> points;
  std::vector<CameraSet> cameras;
  points.reserve(last_points_.points.size());
  cameras.reserve(last_points_.points.size());
  for (const MergedPoint& point : last_points_.points) {
    points.push_back(point.position);
    cameras.push_back(point.cameras);
  }
  last_recognition_ = recognizer_.recognize(points, tracker_.tracked_poses(), cameras);
  tracker_.apply(last_recognition_.robots, last_points_.stamp_ns);

  stats_.ambiguous_pairs += static_cast<uint64_t>(last_recognition_.ambiguous_pairs);
  for (const Recognition& reading : last_recognition_.robots) {
    switch (reading.evidence) {
      case PoseEvidence::AllLeds:
        ++stats_.readings_all_leds;
        break;
      case PoseEvidence::TwoLeds:
        ++stats_.readings_two_leds;
        break;
      case PoseEvidence::OneLed:
        ++stats_.readings_one_led;
        break;
    }
  }
  return SampleStatus::Used;
}

std::vector<TrackedRobot> RobotLocalizer::tracked_robots(int64_t now_ns) {
  tracker_.expire(now_ns);
  std::vector<TrackedRobot> tracked;
  for (const TrackedRobot& robot : tracker_.robots()) {
    if (robot.tracked) tracked.push_back(robot);
  }
  return tracked;
}

}  // namespace mocap::pixart::localization
