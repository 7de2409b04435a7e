// centroid_camera: a motion-capture camera that sends centroids, not images: a swarm scene's
// markers (swarm_scene_file.hpp) projected to fiducials (centroid_camera.hpp) and published on
// /mocap/fiducials (a volume's launch file remaps it to /volume/<camera>/fiducials), with each
// robot's true pose on /camera/ir/ground_truth (frame 'world'), for the evaluator, while a
// subscriber reads it.
//
// The cameras of a volume capture together (capture_clock.hpp). The scene's
// time counts from the launch's start (mocap/launch_start.hpp), so cameras in different
// processes show the same instant; without a launcher, from this component's start. Past its
// duration the robots hold their last places.
#include <chrono>
#include <memory>
#include <string>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/launch_start.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "common/capture_clock/capture_clock.hpp"
#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "sim/centroid_camera/centroid_camera.hpp"
#include "sim/swarm_scene/swarm_scene_file.hpp"

namespace mocap::synthetic {
namespace {

using mocap_msgs::msg::ConstellationPoseArray;
using mocap_msgs::msg::FiducialArray;

// A truth's velocity: the scene's poses this far apart on either side (seconds).
constexpr double kVelocityStep_s = 1e-3;

struct Settings {
  std::string camera = mocap::config_file("volume/cameras/cam_0.yaml");
  std::string scene = mocap::config_file("swarm/scene.yaml");
  double rate_hz = 240;
  CentroidCameraOptions centroids;
  // Each robot's frame hides what lies behind it: a sphere of this radius under its origin.
  double body_radius_m = 0.03;
  int64_t seed = 1;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("camera", "the camera file, with the camera's `pose` in the volume", &Settings::camera)
        .path()
        .add("scene", "the swarm scene: layouts and groups of robots (swarm_scene_file.hpp)",
             &Settings::scene)
        .path()
        .add("rate_hz", "frames per second, taken together with the volume's other cameras",
             &Settings::rate_hz)
        .range(1, 2000)
        .add("noise_px", "1-sigma error of a centroid along each image axis", &Settings::centroids,
             &CentroidCameraOptions::noise_px)
        .range(0, 10)
        .add("marker_diameter_m", "the markers' diameter", &Settings::centroids,
             &CentroidCameraOptions::marker_diameter_m)
        .range(0.001, 0.2)
        .add("body_radius_m",
             "each robot hides what lies behind it: a sphere of this radius under its origin; 0: "
             "none",
             &Settings::body_radius_m)
        .range(0, 1)
        .add("seed", "the noise's seed (each camera's own: give each a different one)",
             &Settings::seed)
        .range(0, INT32_MAX);

class CentroidCameraComponent final : public Component {
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "A motion-capture camera that sends centroids: a swarm scene's markers projected to "
        "fiducials with the sensor's sub-pixel noise, merged where their images touch, hidden "
        "behind robots and the scene's occluders, and cut by the image's edge; no image is "
        "rendered. Frames are taken at multiples of the period on the system clock, the "
        "scene's time counted from the launch's start.");
    kParameters.declare(spec);
    spec.publishes<FiducialArray>(topics::kFiducials, Qos::sensor_data(),
                                  "the centroids of each frame, stamped with its capture time");
    spec.publishes<ConstellationPoseArray>(
        topics::kGroundTruth, Qos::reliable(),
        "each robot's true pose and velocity at each capture time, frame 'world'");
  }

  explicit CentroidCameraComponent(Context& context) : Component(context) {
    const calibration::CameraFile file = calibration::load_camera_file(settings_.camera);
    if (!file.world_from_camera) {
      throw std::invalid_argument(settings_.camera +
                                  ": no `pose`: a volume camera needs its place in the world");
    }
    frame_id_ = file.frame_id;
    scene_ = load_swarm_scene(settings_.scene);
    camera_ = std::make_unique<CentroidCamera>(file.model, file.world_from_camera->inverse(),
                                               settings_.centroids,
                                               static_cast<uint64_t>(settings_.seed));
    scene_start_ = launch_start().value_or(std::chrono::system_clock::now());
    fiducials_ = create_publisher<FiducialArray>(topics::kFiducials);
    truths_ = create_publisher<ConstellationPoseArray>(topics::kGroundTruth);
    const auto period = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(1 / settings_.rate_hz));
    create_worker("capture", [this, period](std::stop_token stop) {
      capture_on_the_clock(period, stop, [this](Clock::time_point capture) { frame(capture); });
    });
    size_t markers = 0;
    for (const SwarmSceneRobot& robot : scene_.robots) markers += robot.markers.size();
    log().info("{} robots ({} markers) of {} seen from {} at {} Hz on {}", scene_.robots.size(),
               markers, settings_.scene, settings_.camera, settings_.rate_hz, fiducials_.topic());
  }

  void report_health(HealthReport& report) override {
    rate_.report(report, "frames", settings_.rate_hz,
                 "the capture thread misses its times: the host is too busy");
    latency_.report(report, "capture -> fiducials sent");
  }

 private:
  void frame(Clock::time_point stamp) {
    const double time_s =
        std::chrono::duration<double>(stamp.time_since_epoch() - scene_start_.time_since_epoch())
            .count();
    std::vector<Eigen::Isometry3d> poses;
    std::vector<Eigen::Vector3d> markers;
    std::vector<OccludingSphere> hiding = scene_.occluders;  // and each robot, below
    poses.reserve(scene_.robots.size());
    hiding.reserve(hiding.size() + scene_.robots.size());
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      poses.push_back(scene_.pose(r, time_s));
      for (const Eigen::Vector3d& marker : scene_.robots[r].markers) {
        markers.push_back(poses.back() * marker);
      }
      if (settings_.body_radius_m > 0) {
        hiding.push_back(
            {poses.back().translation() - Eigen::Vector3d(0, 0, settings_.body_radius_m),
             settings_.body_radius_m});
      }
    }
    std_msgs::msg::Header header;
    header.stamp(to_time_msg(stamp));
    header.frame_id(frame_id_);
    auto fiducials = std::make_shared<FiducialArray>();
    fiducials->header(header);
    const std::vector<Centroid> centroids = camera_->project(markers, hiding);
    fiducials->fiducials().reserve(centroids.size());
    for (const Centroid& centroid : centroids) {
      mocap_msgs::msg::Fiducial fiducial;
      fiducial.x(static_cast<float>(centroid.pixel.x()));
      fiducial.y(static_cast<float>(centroid.pixel.y()));
      // The blob's area, as a detector reports it.
      fiducial.size(
          static_cast<float>(3.14159265 / 4 * centroid.diameter_px * centroid.diameter_px));
      fiducial.uncertainty(static_cast<float>(centroid.sigma_px));
      fiducials->fiducials().push_back(fiducial);
    }
    fiducials_.publish(std::move(fiducials));
    latency_.add(now() - stamp);
    rate_.add();
    // The truth after the centroids, which it would otherwise delay, and only while someone
    // reads it (in the demos, the one camera whose truth the evaluator takes): it costs as
    // much as the centroids.
    if (truths_.matched_subscribers() == 0) return;
    header.frame_id("world");
    auto truth = std::make_shared<ConstellationPoseArray>();
    truth->header(header);
    for (size_t r = 0; r < scene_.robots.size(); ++r) {
      const Eigen::Vector3d velocity = (scene_.pose(r, time_s + kVelocityStep_s).translation() -
                                        scene_.pose(r, time_s - kVelocityStep_s).translation()) /
                                       (2 * kVelocityStep_s);
      mocap_msgs::msg::ConstellationPose robot;
      robot.name(scene_.robots[r].name);
      robot.pose().header(header);
      robot.pose().pose(to_pose_message(poses[r]));
      robot.velocity(to_twist_message(velocity, Eigen::Vector3d::Zero()));
      robot.points_used(static_cast<uint32_t>(scene_.robots[r].markers.size()));
      truth->poses().push_back(std::move(robot));
    }
    truths_.publish(std::move(truth));
  }

  SwarmScene scene_;
  LatencyFigures latency_;  // added by the capture thread
  RateFigures rate_;
  std::unique_ptr<CentroidCamera> camera_;  // only the capture thread uses it
  std::string frame_id_;
  std::chrono::system_clock::time_point scene_start_;
  Publisher<FiducialArray> fiducials_;
  Publisher<ConstellationPoseArray> truths_;
};

}  // namespace
}  // namespace mocap::synthetic

MOCAP_REGISTER_COMPONENT(mocap::synthetic::CentroidCameraComponent, "centroid_camera")
