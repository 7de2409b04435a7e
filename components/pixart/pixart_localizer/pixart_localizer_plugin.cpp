// pixart_localizer: every PixArt camera's fiducial arrays -> robot poses x, y, θ in the world
// frame (pixart_localizer.hpp), published at a steady rate whether the robots move or not.
//
// publish_rate_hz: 0 publishes after every sample used instead, for consumers that want each
// sample's result at once (a timer adds up to one period of latency, 20 ms at the default
// 50 Hz). Nothing is published then while no sample arrives: robots whose cameras all fall
// silent stay in the last array, where the steady rate would drop them after lost_after_s.
#include <chrono>
#include <cmath>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/camera_footprint_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <mocap_msgs/msg/robot_pose_array.hpp>

#include "common/topics/graph_topics.hpp"
#include "pixart/pixart_localizer/led_plane_points.hpp"
#include "pixart/pixart_localizer/pixart_localizer.hpp"
#include "pixart/pixart_rig/pixart_rig.hpp"

namespace mocap::pixart::localization {
namespace {

using mocap_msgs::msg::CameraFootprintArray;
using mocap_msgs::msg::FiducialArray;
using mocap_msgs::msg::RobotPoseArray;

double degrees(double radians) { return radians * 180.0 / M_PI; }

// The localizer's options with what only the plugin reads.
struct Settings : LocalizerOptions {
  std::string rig = mocap::config_file("pixart/rig.yaml");
  double publish_rate_hz = 50;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("rig", "the rig: cameras, LED plane height, robots' LED layouts", &Settings::rig)
        .path()
        .add("merge_distance_m", "points of two cameras closer than this are one LED",
             &Settings::merging, &MergeOptions::merge_distance_m)
        .range(1e-4, 1)
        .add("merge_window_s", "... if their samples were taken within this of each other",
             &Settings::merging, &MergeOptions::merge_window_s)
        .range(0, 1)
        .add("stale_after_s",
             "a camera whose last sample is older than this (against the newest) is "
             "left out",
             &Settings::merging, &MergeOptions::stale_after_s)
        .range(1e-3, 10)
        .add("pattern_tolerance_m", "how far LED distances may be from a robot's layout",
             &Settings::recognition, &RecognitionOptions::pattern_tolerance_m)
        .range(1e-4, 0.1)
        .add("tracking_gate_m",
             "how far a robot's steady LED may be from its tracked place, for readings "
             "of 2 LEDs and of 1",
             &Settings::recognition, &RecognitionOptions::tracking_gate_m)
        .range(1e-3, 10)
        .add("publish_rate_hz",
             "rate of /pixart/robots; 0 = after every sample used (no timer: nothing is "
             "published while no sample arrives)",
             &Settings::publish_rate_hz)
        .range(0, 1000)
        .add("lost_after_s", "a robot not seen for this long is dropped", &Settings::tracking,
             &TrackingOptions::lost_after_s)
        .range(0.01, 3600);

class PixartLocalizer final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Localizes robots carrying the seed's blinking LED pattern under the PixArt ceiling "
        "cameras: each camera's points onto the LED plane, the same LED seen by overlapping "
        "cameras merged, robots recognised by their LED spacings, x, y, theta published for "
        "every tracked robot (also while it stands still).");
    kParameters.declare(spec);
    spec.subscribes<FiducialArray>(
        topics::kPixartFiducials, Qos::reliable(),
        "one topic per rig camera: its points in pixels, frame id = the camera's rig name");
    spec.publishes<RobotPoseArray>(
        topics::kPixartRobots, Qos::reliable(),
        "every tracked robot's x, y (m) and theta (rad) in frame 'world', stamped with the "
        "newest sample used");
    spec.publishes<CameraFootprintArray>(
        topics::kPixartFootprints, Qos::latched(),
        "once: what each rig camera sees of the LED plane (its image corners there), frame "
        "'world', for viewers");
  }

  explicit PixartLocalizer(Context& context)
      : Component(context), localizer_(load_rig(settings_.rig), settings_) {
    const Rig& rig = localizer_.rig();
    for (const std::string& problem : localizer_.recognizer().unsupported()) {
      log().warn("{}: not localized", problem);
    }
    publisher_ = create_publisher<RobotPoseArray>(topics::kPixartRobots);
    publish_footprints(rig);
    for (const RigCamera& camera : rig.cameras) {
      create_subscription<FiducialArray>(
          topics::member_of(topics::kPixartFiducials, camera.name),
          [this, name = camera.name](const FiducialArray& array) { on_sample(name, array); });
    }
    if (const double rate = settings_.publish_rate_hz; rate > 0) {
      create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::duration<double>(1.0 / rate)),
                   [this] { publish(); });
    } else {
      publish_every_sample_ = true;
    }
    log().info("{} robots, {} cameras, LED plane at {} m (rig {})",
               rig.robots.size() - localizer_.recognizer().unsupported().size(), rig.cameras.size(),
               rig.led_plane_height_m, rig.source);
  }

  ~PixartLocalizer() override {
    const LocalizerStats& s = localizer_.stats();
    log().info(
        "{} samples used, {} pose arrays published; readings: {} from 3 LEDs, {} from 2 LEDs, "
        "{} from one LED, {} ambiguous LED pairs; ignored: {} arrays from cameras not "
        "in the rig, {} non-finite points, {} points off the LED plane, {} out-of-order samples",
        s.samples, published_, s.readings_all_leds, s.readings_two_leds, s.readings_one_led,
        s.ambiguous_pairs, s.unknown_camera_samples, s.non_finite_pixels, s.unprojectable_pixels,
        s.out_of_order_samples);
  }

 private:
  void publish_footprints(const Rig& rig) {
    auto footprints = std::make_shared<CameraFootprintArray>();
    footprints->header().stamp(to_time_msg(now()));
    footprints->header().frame_id("world");
    for (const RigCamera& camera : rig.cameras) {
      auto corners = led_plane_footprint(camera, rig.led_plane_height_m);
      if (!corners) {
        log().warn("{} does not see the LED plane whole; no footprint", camera.name);
        continue;
      }
      mocap_msgs::msg::CameraFootprint footprint;
      footprint.name(camera.name);
      for (const Eigen::Vector2d& corner : *corners) {
        geometry_msgs::msg::Point point;
        point.x(corner.x());
        point.y(corner.y());
        point.z(rig.led_plane_height_m);
        footprint.corners().push_back(point);
      }
      footprints->cameras().push_back(std::move(footprint));
    }
    footprints_ = create_publisher<CameraFootprintArray>(topics::kPixartFootprints);
    footprints_.publish(std::move(footprints));
  }

  // `topic_camera`: the rig camera whose topic carried the array. The array's frame id names
  // the camera that took it (the bridge's camera_names); that is the one it is projected
  // through, and a mismatch, a sign of misconfigured names, is reported once.
  void on_sample(const std::string& topic_camera, const FiducialArray& array) {
    const std::string& frame = array.header().frame_id();
    const std::string& camera = frame.empty() ? topic_camera : frame;
    if (camera != topic_camera && mismatched_topics_.insert(topic_camera).second) {
      log().warn("the topic of camera '{}' carries arrays of frame '{}'; using '{}'", topic_camera,
                 frame, frame);
    }
    pixels_.clear();
    for (const auto& fiducial : array.fiducials()) pixels_.emplace_back(fiducial.x(), fiducial.y());
    std::optional<int64_t> newest_before = localizer_.newest_sample_ns();
    auto status = localizer_.add_sample(camera, to_nanoseconds(array.header().stamp()), pixels_);
    if (status == RobotLocalizer::SampleStatus::UnknownCamera &&
        unknown_cameras_.insert(camera).second) {
      log().warn("arrays of camera '{}' are ignored: it is not in the rig {}", camera,
                 localizer_.rig().source);
    }
    if (localizer_.newest_sample_ns() != newest_before) {
      newest_arrived_ = std::chrono::steady_clock::now();
    }
    if (publish_every_sample_ && status == RobotLocalizer::SampleStatus::Used) {
      publish();  // reports the events too
    } else {
      report_events();
    }
  }

  void publish() {
    std::optional<int64_t> newest = localizer_.newest_sample_ns();
    if (!newest) return;  // nothing seen yet
    // Sample time goes on with the machine's clock while no sample arrives, so robots are
    // dropped after lost_after_s also when every camera falls silent.
    auto silence = std::chrono::steady_clock::now() - newest_arrived_;
    int64_t now_ns =
        *newest + std::chrono::duration_cast<std::chrono::nanoseconds>(silence).count();
    std::vector<TrackedRobot> robots = localizer_.tracked_robots(now_ns);
    report_events();

    auto message = std::make_shared<RobotPoseArray>();
    int64_t stamp_ns = robots.empty() ? *newest : robots.front().last_seen_ns;
    for (const TrackedRobot& robot : robots) {
      stamp_ns = std::max(stamp_ns, robot.last_seen_ns);
      mocap_msgs::msg::RobotPose pose;
      pose.name(robot.name);
      pose.x(robot.pose.x);
      pose.y(robot.pose.y);
      pose.theta(robot.pose.theta);
      message->robots().push_back(std::move(pose));
    }
    message->header().stamp(to_time_msg(Clock::time_point(std::chrono::nanoseconds(stamp_ns))));
    message->header().frame_id("world");
    publisher_.publish(std::move(message));
    ++published_;
  }

  void report_events() {
    for (const TrackEvent& event : localizer_.take_events()) {
      const TrackedRobot& robot = localizer_.tracker().robots()[event.robot];
      if (event.kind == TrackEvent::Kind::Found) {
        log().info("{} found at x {:.3f} m, y {:.3f} m, theta {:.1f} deg ({})", robot.name,
                   robot.pose.x, robot.pose.y, degrees(robot.pose.theta),
                   to_string(robot.evidence));
      } else {
        log().info("{} lost: not seen for {} s (last at x {:.3f} m, y {:.3f} m)", robot.name,
                   localizer_.options().tracking.lost_after_s, robot.pose.x, robot.pose.y);
      }
    }
  }

  RobotLocalizer localizer_;
  Publisher<CameraFootprintArray> footprints_;  // latched: published once
  Publisher<RobotPoseArray> publisher_;
  std::vector<Eigen::Vector2d> pixels_;  // reused between samples
  std::chrono::steady_clock::time_point newest_arrived_ = std::chrono::steady_clock::now();
  std::set<std::string> unknown_cameras_;
  std::set<std::string> mismatched_topics_;
  bool publish_every_sample_ = false;  // publish_rate_hz 0
  uint64_t published_ = 0;
};

}  // namespace
}  // namespace mocap::pixart::localization

MOCAP_REGISTER_COMPONENT(mocap::pixart::localization::PixartLocalizer, "pixart_localizer")
