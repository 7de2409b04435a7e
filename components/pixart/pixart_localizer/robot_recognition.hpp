// Step 3 of the localizer: which robot is where, from the LEDs seen on the LED plane.
//
// The seed's robot (seed 002 §1) carries three LEDs on a line along its heading at unequal
// spacing: the middle one, at the robot's origin, always on; the two ends blinking, each at
// its own rate. So at any instant a robot shows three, two or one of its LEDs, and the
// recognizer uses the most telling reading first, each point for one robot at most and each
// robot at most once:
//
//   1. Three LEDs. Every triple of points is compared with every robot's layout: the three
//      pairwise distances must match the layout's within `pattern_tolerance_m`, and the
//      rigid fit of the layout onto the points (no reflection) must leave every LED within
//      the tolerance. Unequal spacings make the assignment unique, so the fit gives the
//      position (the robot origin) and the heading (robot +x: from the rear LED to the front
//      LED) at once. Matches are accepted best fit first, so a triple mixing two robots'
//      LEDs loses to the true one.
//   2. Two LEDs: the steady LED and one blinking end. A pair whose distance matches one
//      robot's steady-to-end spacing identifies that robot only if no other LED distance of
//      any robot lies within twice the tolerance of that spacing (else it is ambiguous, the
//      pair is left to step 3 and the heading is kept). Which of the two points is the steady
//      LED the pair cannot say; the robot's tracked pose can: of the two assignments, the one
//      that puts both LEDs nearer (summed distance) where the tracked pose has them, accepted
//      when the steady LED is within `tracking_gate_m` of its tracked place. An untracked
//      robot is not initialised from two LEDs.
//   3. One LED: a point left over from 1 and 2 that lies within `tracking_gate_m` of where one
//      of a tracked robot's LEDs (not yet found) should be moves that robot so that LED lands
//      on it, keeping its heading; the nearest point–LED pairs are taken first. Usually it is
//      the steady LED, but a sensor reports only 4 points, and with more LEDs in its view the
//      steady one may be among those dropped while a blinking end is reported.
//
// In steps 1 and 2, LEDs seen together by one camera are preferred to LEDs combined across
// cameras: one camera places its points consistently with each other, while two cameras
// disagree by their calibration errors (centimetres for cameras not yet calibrated), and a
// pair or triple across them can fit a layout in a wrong orientation. Across cameras is the
// fallback, for a robot no single camera sees enough of.
//
// Robots the recognizer cannot tell apart or orient are set aside when it is built, each
// with the reason (unsupported()): it needs exactly three LEDs, one of them steady (off_s 0)
// and the three pairwise distances apart by more than twice the tolerance.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pixart/pixart_localizer/planar_fit.hpp"
#include "pixart/pixart_localizer/point_merging.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace mocap::pixart::localization {

struct RecognitionOptions {
  // How far an LED distance may be from the layout's (pixel rounding moves a point by up to
  // ~1 mm at 2 m; calibration errors add more). The default rig's spacings differ by 20 mm.
  double pattern_tolerance_m = 0.008;
  // How far a steady LED may be from where its tracked robot had it, for steps 2 and 3.
  double tracking_gate_m = 0.1;

  // Why these options cannot be used, naming the field ("tracking_gate_m: 0 is not above 0");
  // nullopt when they can. RobotRecognizer's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// How a pose was measured.
enum class PoseEvidence {
  AllLeds,  // step 1: position and heading
  TwoLeds,  // step 2: position and heading, the steady LED told apart by tracking
  OneLed,   // step 3: position; heading kept from before
};
const char* to_string(PoseEvidence evidence);  // "3 LEDs", "2 LEDs", "one LED"

struct Recognition {
  size_t robot = 0;  // index into the rig's robots
  PlanarPose pose;
  PoseEvidence evidence = PoseEvidence::AllLeds;
  std::vector<size_t> points;  // indices of the points used
  double rms_residual_m = 0;   // of the layout fit (0 for a single LED)
};

struct RecognitionResult {
  std::vector<Recognition> robots;
  std::vector<size_t> unexplained_points;  // used by no robot
  int ambiguous_pairs = 0;                 // two-LED readings several robots could give
};

class RobotRecognizer {
 public:
  explicit RobotRecognizer(const std::vector<RobotModel>& robots, RecognitionOptions options = {});

  // `tracked[i]`: robot i's last pose if it is being tracked, else nullopt (size: the rig's
  // robot count; missing entries count as untracked). `cameras[i]`: the cameras that saw
  // point i; empty: one camera saw them all.
  RecognitionResult recognize(const std::vector<Eigen::Vector2d>& points,
                              const std::vector<std::optional<PlanarPose>>& tracked,
                              const std::vector<CameraSet>& cameras = {}) const;

  // Whether robot `robot` (rig index) can be recognised; the reasons for those that cannot,
  // "robot 'name': why".
  bool supported(size_t robot) const { return patterns_.at(robot).has_value(); }
  const std::vector<std::string>& unsupported() const { return unsupported_; }
  // The smallest distance between two LEDs of one supported robot (0 if none is supported):
  // LEDs closer than the merge distance would be merged into one.
  double smallest_led_distance_m() const;
  const RecognitionOptions& options() const { return options_; }

 private:
  struct Pattern {
    std::array<Eigen::Vector2d, 3> leds;  // robot frame
    size_t steady = 0;                    // the always-on LED
    // distance[a][b] between LEDs a and b.
    std::array<std::array<double, 3>, 3> distance{};
    // Per LED: whether two LEDs at the distance steady–this LED name this robot alone.
    std::array<bool, 3> identifying_spacing{};
  };

  void find_triples(const std::vector<Eigen::Vector2d>& points,
                    const std::vector<CameraSet>& cameras, std::vector<bool>& used,
                    std::vector<bool>& found, RecognitionResult& result) const;
  void find_pairs(const std::vector<Eigen::Vector2d>& points,
                  const std::vector<std::optional<PlanarPose>>& tracked,
                  const std::vector<CameraSet>& cameras, std::vector<bool>& used,
                  std::vector<bool>& found, RecognitionResult& result) const;
  void find_single_leds(const std::vector<Eigen::Vector2d>& points,
                        const std::vector<std::optional<PlanarPose>>& tracked,
                        std::vector<bool>& used, std::vector<bool>& found,
                        RecognitionResult& result) const;

  RecognitionOptions options_;
  std::vector<std::optional<Pattern>> patterns_;  // per rig robot; nullopt: unsupported
  std::vector<std::string> unsupported_;
};

}  // namespace mocap::pixart::localization
