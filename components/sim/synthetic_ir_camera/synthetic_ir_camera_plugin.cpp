// synthetic_ir_camera: renders a scene (ir_renderer.hpp) into mono8 images and publishes them
// with the ground truth of each frame, the embedded default camera when there is no hardware.
//
// Frame k shows the scene at time k * time_step_s (by default 1 / rate_hz): scene time follows
// the frame count, not the wall clock, so a run renders the same frames whatever the load of
// the machine. Headers carry the wall-clock time of publication; an image and its ground truth
// share header stamp and frame id, so consumers pair them by stamp.
//
// With moving_camera the camera is carried around (a turret on a mobile base, see
// mobile_base_sim): its pose in the world (x forward, y left, z up) arrives on /sim/camera_pose
// and each frame is rendered from the latest pose; frames wait for the first pose. The scene
// then describes the world as a camera at the world's origin looking along its x axis would
// see it (scene x = world −y, y = world −z, z = world x), so a scene reads the same for a
// fixed camera and for one that starts at the origin.
//
// A camera file with a `pose` places the camera in a volume: it stands there, the scene is in
// the world's frame (z up) and the ground truth too (frame 'world'). With `synchronized`, the
// cameras of a volume capture together: frames are taken at multiples of the period on the
// system clock, stamped with that time, and each shows the scene at that time (seconds since
// midnight UTC), so cameras in different processes, on hosts with synchronized clocks, show
// the same instant in frames of the same stamp. A frame whose time passed while the previous
// one rendered is skipped, as a real camera drops it. The frames are then taken on a thread of
// their own, sleeping until each capture time, where a timer would fire at any phase.
#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/camera_info.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "common/capture_clock/capture_clock.hpp"
#include "common/image_message/camera_info_message.hpp"
#include "common/image_message/image_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "sim/synthetic_ir_camera/ir_renderer.hpp"
#include "sim/synthetic_ir_camera/scene.hpp"
#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/constellation_database/database_parameters.hpp"

namespace mocap::synthetic {
namespace {

// With rate_hz 0 frames follow each other as fast as they render: the timer only has to fire
// again before a frame is done, and a faster timer would only wake its thread for nothing.
constexpr std::chrono::microseconds kBackToBackPeriod{200};
constexpr double kDefaultTimeStep_s = 1.0 / 30;

// The scene's frame in the world's, for moving_camera: an optical frame at the origin looking
// along world x.
Eigen::Isometry3d world_from_scene() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return pose;
}

struct Settings {
  std::string scene = mocap::config_file("scenes/demo.yaml");
  std::string camera = mocap::config_file("cameras/synthetic_ir_1280x720.yaml");
  constellations::DatabaseFiles boards;
  double rate_hz = 30.0;
  double time_step_s = 0.0;
  std::string frame_id;
  int max_frames = 0;
  bool wait_for_subscriber = true;
  bool moving_camera = false;
  bool synchronized = false;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("scene",
             "scene file: objects, trajectories, rendering, distractors "
             "(config/scenes/README.md)",
             &Settings::scene)
        .path()
        .add("camera", "camera file (ROS camera_info YAML): image size and lens", &Settings::camera)
        .path()
        .include(&Settings::boards, constellations::database_parameters())
        .add("rate_hz", "frames per second; 0 = as fast as they render", &Settings::rate_hz)
        .range(0, 10000)
        .add("time_step_s",
             "scene time between frames, seconds; 0 = 1 / rate_hz (1/30 when rate_hz is 0)",
             &Settings::time_step_s)
        .range(0, 3600)
        .add("frame_id", "frame id of the headers; empty = the camera file's", &Settings::frame_id)
        .add("max_frames", "frames to publish before stopping; 0 = no limit", &Settings::max_frames)
        .min(0)
        .add("wait_for_subscriber",
             "hold the first frame until the image topic has a subscriber, so a run "
             "across processes starts with frame 0 however long discovery takes",
             &Settings::wait_for_subscriber)
        .add("moving_camera",
             "false: the camera stands still and the scene is in its frame; true: its pose "
             "in the world comes on " +
                 std::string(topics::kSimCameraPose) +
                 " and the scene is as seen from the world's origin looking along x",
             &Settings::moving_camera)
        .add("synchronized",
             "frames at multiples of the period on the system clock, stamped with that time "
             "and showing the scene at it: the cameras of a volume capture together",
             &Settings::synchronized);

class SyntheticIrCamera final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Renders constellations moving through a scene, distractor lights and sensor noise "
        "into mono8 infrared images, and publishes each frame's ground truth. Frame k shows "
        "scene time k * time_step_s, whatever the wall clock does, so runs are reproducible.");
    kParameters.declare(spec);
    spec.subscribes<geometry_msgs::msg::PoseStamped>(
        topics::kSimCameraPose, Qos::reliable(),
        "moving_camera: the camera's optical frame in the world (e.g. from mobile_base_sim)");
    spec.publishes<sensor_msgs::msg::Image>(topics::kCameraImage, Qos::sensor_data(),
                                            "rendered frames, mono8");
    spec.publishes<sensor_msgs::msg::CameraInfo>(
        topics::kCameraInfo, Qos::sensor_data(),
        "the camera file's lens with each frame, same header (pinhole cameras only)");
    spec.publishes<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kGroundTruth, Qos::reliable(),
        "per frame, the true pose and velocity of every constellation in front of the camera "
        "(camera frame, or 'world' for a camera placed by its file; mid-exposure); points_used = "
        "its "
        "visible markers; same stamp as the image");
  }

  explicit SyntheticIrCamera(Context& context) : Component(context) {
    // Load errors propagate: the runtime reports them with this component's name.
    calibration::CameraFile camera = calibration::load_camera_file(settings_.camera);
    constellations::ConstellationDatabase database = settings_.boards.load();
    Scene scene = load_scene(settings_.scene, database);
    size_t object_count = scene.objects.size();
    renderer_ = std::make_unique<IrRenderer>(std::move(scene), camera.model);

    frame_id_ = settings_.frame_id;
    if (frame_id_.empty()) frame_id_ = camera.frame_id;
    wait_for_subscriber_ = settings_.wait_for_subscriber;
    double rate_hz = settings_.rate_hz;
    time_step_s_ = settings_.time_step_s;
    if (time_step_s_ == 0) time_step_s_ = rate_hz > 0 ? 1 / rate_hz : kDefaultTimeStep_s;

    if (settings_.synchronized && (rate_hz <= 0 || settings_.moving_camera)) {
      throw std::invalid_argument("synchronized: needs a rate_hz above 0 and a fixed camera");
    }
    if (settings_.moving_camera) {
      create_subscription<geometry_msgs::msg::PoseStamped>(
          topics::kSimCameraPose, [this](const geometry_msgs::msg::PoseStamped& pose) {
            if (std::optional<Eigen::Isometry3d> world_from_camera = to_isometry(pose.pose())) {
              camera_from_world_ = world_from_camera->inverse() * world_from_scene();
            }
          });
    } else if (camera.world_from_camera) {
      world_from_camera_ = *camera.world_from_camera;
      camera_from_world_ = camera.world_from_camera->inverse();
    } else {
      camera_from_world_ = Eigen::Isometry3d::Identity();
    }
    images_ = create_publisher<sensor_msgs::msg::Image>(topics::kCameraImage);
    if (auto info = camera_info_message(*camera.model)) {
      camera_info_ = std::move(*info);
      infos_ = create_publisher<sensor_msgs::msg::CameraInfo>(topics::kCameraInfo);
    }
    truths_ = create_publisher<mocap_msgs::msg::ConstellationPoseArray>(topics::kGroundTruth);
    std::chrono::nanoseconds period = rate_hz > 0
                                          ? std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                std::chrono::duration<double>(1 / rate_hz))
                                          : std::chrono::nanoseconds(kBackToBackPeriod);
    if (settings_.synchronized) {
      // The only caller of tick() then (no timer, no pose subscription): it needs no lock.
      create_worker("capture", [this, period](std::stop_token stop) {
        capture_on_the_clock(period, stop, [this](Clock::time_point capture) { tick(capture); });
      });
    } else {
      create_timer(period, [this] { tick(); });
    }
    log().info("{}x{} frames of {} ({} objects) at {} on {}, scene time step {:.6g} s",
               camera.model->width(), camera.model->height(), settings_.scene, object_count,
               rate_hz > 0 ? fmt::format("{} Hz", rate_hz) : "full speed", images_.topic(),
               time_step_s_);
  }

  void report_health(HealthReport& report) override {
    if (settings_.rate_hz > 0) {
      rate_.report(report, "frames", settings_.rate_hz,
                   "rendering takes longer than a frame period: the host is too busy");
    }
    latency_.report(report, "capture -> image sent");
  }

 private:
  // `capture`: the synchronized capture time; none: now, and scene time by the frame count.
  void tick(std::optional<Clock::time_point> capture = std::nullopt) {
    if (wait_for_subscriber_) {
      if (images_.matched_subscribers() == 0) {
        if (!reported_waiting_) log().info("waiting for a subscriber on {}", images_.topic());
        reported_waiting_ = true;
        return;
      }
      wait_for_subscriber_ = false;
    }
    if (settings_.max_frames > 0 && frames_ >= static_cast<uint64_t>(settings_.max_frames)) {
      if (!reported_end_) {
        log().info("published {} frames (max_frames); no more", frames_);
        reported_end_ = true;
      }
      return;
    }
    if (!camera_from_world_) {
      if (!reported_no_pose_)
        log().info("waiting for the camera's pose on {}", topics::kSimCameraPose);
      reported_no_pose_ = true;
      return;
    }
    const Clock::time_point stamp = capture.value_or(now());
    double scene_time_s = static_cast<double>(frames_) * time_step_s_;
    if (capture) {
      const int64_t day_ns = int64_t{86400} * 1'000'000'000;
      scene_time_s = static_cast<double>(stamp.time_since_epoch().count() % day_ns) * 1e-9;
    }
    RenderedFrame frame = renderer_->render(scene_time_s, frames_, *camera_from_world_);
    ++frames_;

    std_msgs::msg::Header header;
    header.stamp(to_time_msg(stamp));
    header.frame_id(frame_id_);
    std_msgs::msg::Header truth_header = header;
    if (world_from_camera_) truth_header.frame_id("world");

    auto image = std::make_shared<sensor_msgs::msg::Image>();
    image->header(header);
    fill_image_message(frame.image, *image);

    auto truth = std::make_shared<mocap_msgs::msg::ConstellationPoseArray>();
    truth->header(truth_header);
    // Into the world's frame for a placed camera: its rotation turns the velocities too.
    const Eigen::Isometry3d to_truth_frame =
        world_from_camera_.value_or(Eigen::Isometry3d::Identity());
    for (const ObjectTruth& object : frame.objects) {
      if (!object.in_front) continue;
      const Eigen::Vector3d linear = to_truth_frame.linear() * object.linear_velocity;
      const Eigen::Vector3d angular = to_truth_frame.linear() * object.angular_velocity;
      mocap_msgs::msg::ConstellationPose pose;
      pose.name(object.constellation);
      pose.pose().header(truth_header);
      pose.pose().pose(to_pose_message(to_truth_frame * object.pose));
      pose.reprojection_rms_px(0);
      pose.points_used(static_cast<uint32_t>(object.visible_markers()));
      pose.velocity(to_twist_message(linear, angular));
      truth->poses().push_back(std::move(pose));
    }
    images_.publish(std::move(image));
    latency_.add(now() - stamp);
    rate_.add();
    truths_.publish(std::move(truth));
    if (infos_) {
      auto info = std::make_shared<sensor_msgs::msg::CameraInfo>(camera_info_);
      info->header(header);
      infos_.publish(std::move(info));
    }
  }

  std::unique_ptr<IrRenderer> renderer_;
  sensor_msgs::msg::CameraInfo camera_info_;  // without header
  std::string frame_id_;
  bool wait_for_subscriber_ = true;
  bool reported_waiting_ = false;
  double time_step_s_ = 0;
  uint64_t frames_ = 0;
  bool reported_end_ = false;
  bool reported_no_pose_ = false;
  // The camera's place; none until the first pose arrives (moving_camera). Callbacks of one
  // component never overlap, so the pose callback and tick() share it without a lock.
  std::optional<Eigen::Isometry3d> camera_from_world_;
  std::optional<Eigen::Isometry3d> world_from_camera_;  // a camera placed by its file's pose
  Publisher<sensor_msgs::msg::Image> images_;
  Publisher<mocap_msgs::msg::ConstellationPoseArray> truths_;
  Publisher<sensor_msgs::msg::CameraInfo> infos_;  // none for a lens camera_info cannot describe
  LatencyFigures latency_;                         // added by the capture thread when synchronized
  RateFigures rate_;
};

}  // namespace
}  // namespace mocap::synthetic

MOCAP_REGISTER_COMPONENT(mocap::synthetic::SyntheticIrCamera, "synthetic_ir_camera")
