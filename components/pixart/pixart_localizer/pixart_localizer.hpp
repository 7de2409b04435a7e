// The PixArt localizer without middleware: camera samples in, robot poses (x, y, θ on the LED
// plane, world frame) out. Each sample goes through these steps:
//
//   led_plane_points.hpp   the sample's pixels onto the LED plane, through the rig's cameras
//   camera_views.hpp       kept as the camera's latest view
//   point_merging.hpp      the fresh views merged: one point per LED
//   robot_recognition.hpp  robots named and placed by their LED patterns
//   robot_tracking.hpp     poses kept between readings; robots not read for a while dropped
//
// Time is the samples' own (their stamps, ns), never the clock of the machine running this:
// a replayed log localizes the same as a live bus. The caller declares robots lost by asking
// for the tracked robots at a time of its choosing (tracked_robots()).
//
//   RobotLocalizer localizer(load_rig("config/pixart/rig.yaml"));
//   localizer.add_sample("camera2", stamp_ns, pixels);   // for every camera sample
//   for (const TrackedRobot& robot : localizer.tracked_robots(now_ns)) publish(robot);
//
// Namespace mocap::pixart::localization: the simulated box's library shares mocap::pixart and
// links into the same test programs, so the localizer's names stay apart from its names.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "pixart/pixart_localizer/camera_views.hpp"
#include "pixart/pixart_localizer/led_plane_points.hpp"
#include "pixart/pixart_localizer/point_merging.hpp"
#include "pixart/pixart_localizer/robot_recognition.hpp"
#include "pixart/pixart_localizer/robot_tracking.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace mocap::pixart::localization {

struct LocalizerOptions {
  MergeOptions merging;
  RecognitionOptions recognition;
  TrackingOptions tracking;

  // Why these options cannot be used, naming the field by its path
  // ("tracking.lost_after_s: 0 is not above 0"); nullopt when they can. RobotLocalizer's
  // constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct LocalizerStats {
  uint64_t samples = 0;                 // used
  uint64_t unknown_camera_samples = 0;  // from a camera not in the rig: ignored
  uint64_t out_of_order_samples = 0;    // older than the camera's latest: ignored
  uint64_t non_finite_pixels = 0;       // NaN or infinite: ignored
  uint64_t unprojectable_pixels = 0;    // the ray misses the LED plane: ignored
  uint64_t readings_all_leds = 0;       // robot readings by evidence (robot_recognition.hpp)
  uint64_t readings_two_leds = 0;
  uint64_t readings_one_led = 0;
  uint64_t ambiguous_pairs = 0;
};

class RobotLocalizer {
 public:
  // Throws std::invalid_argument for options out of range, a rig without cameras, or one none
  // of whose robots can be recognised (the reasons named). Robots that cannot be recognised
  // while others can are listed by recognizer().unsupported() and never reported.
  explicit RobotLocalizer(Rig rig, LocalizerOptions options = {});

  enum class SampleStatus { Used, UnknownCamera, OutOfOrder };

  // One sample of camera `camera` (its rig name): pixel coordinates as the sensor reports
  // them, taken at `stamp_ns`. Localizes the robots from the fresh views of all cameras.
  SampleStatus add_sample(std::string_view camera, int64_t stamp_ns,
                          const std::vector<Eigen::Vector2d>& pixels);

  // Declares lost the robots not read within lost_after_s before `now_ns` (see the
  // tracker's events), then returns the robots still tracked, in the rig's order.
  std::vector<TrackedRobot> tracked_robots(int64_t now_ns);

  // Found and lost events since the last call (robot_tracking.hpp).
  std::vector<TrackEvent> take_events() { return tracker_.take_events(); }

  // The stamp of the newest sample used, or nothing before the first.
  std::optional<int64_t> newest_sample_ns() const { return views_.newest_stamp_ns(); }
  // What the last sample produced: the merged LED points and the recognition from them.
  const MergedPoints& last_points() const { return last_points_; }
  const RecognitionResult& last_recognition() const { return last_recognition_; }

  const Rig& rig() const { return rig_; }
  const RobotRecognizer& recognizer() const { return recognizer_; }
  const RobotTracker& tracker() const { return tracker_; }
  const LocalizerStats& stats() const { return stats_; }
  const LocalizerOptions& options() const { return options_; }

 private:
  Rig rig_;
  LocalizerOptions options_;
  RobotRecognizer recognizer_;
  RobotTracker tracker_;
  LatestCameraViews views_;
  MergedPoints last_points_;
  RecognitionResult last_recognition_;
  LocalizerStats stats_;
};

}  // namespace mocap::pixart::localization
