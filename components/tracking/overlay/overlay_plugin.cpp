// overlay: draws fiducials, identified lines and pose axes on the camera image, publishes the
// picture and saves PNG snapshots (overlay.hpp).
#include <chrono>
#include <filesystem>
#include <map>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "common/image_message/image_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/overlay/overlay.hpp"
#include "tracking/overlay/png_file.hpp"

namespace mocap::overlay {
namespace {

// Frames waiting for their poses; older ones are dropped.
constexpr size_t kPendingFrames = 30;

struct Settings {
  std::string camera = mocap::config_file("cameras/synthetic_ir_1280x720.yaml");
  std::string snapshot_directory;  // empty: no snapshots
  double snapshot_period_s = 1;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("camera", "camera file, to project the pose axes", &Settings::camera)
        .path()
        .add("snapshot_directory", "where PNG snapshots go (empty: none)",
             &Settings::snapshot_directory)
        .path()
        .add("snapshot_period_s", "seconds between snapshots", &Settings::snapshot_period_s)
        .range(0.01, 3600);

class OverlayComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Debug picture: fiducials, identified lines and names, pose axes drawn on the image; "
        "published as bgr8 and saved as PNG snapshots.");
    kParameters.declare(spec);
    spec.subscribes<sensor_msgs::msg::Image>(topics::kCameraImage, Qos::sensor_data(),
                                             "camera images, mono8");
    spec.subscribes<mocap_msgs::msg::FiducialArray>(topics::kFiducials, Qos::reliable(),
                                                    "fiducials");
    spec.subscribes<mocap_msgs::msg::ConstellationArray>(topics::kConstellations, Qos::reliable(),
                                                         "identified constellations");
    spec.subscribes<mocap_msgs::msg::ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                                             "estimated poses; draws the frame");
    spec.publishes<sensor_msgs::msg::Image>(topics::kOverlay, Qos::sensor_data(),
                                            "the picture, bgr8");
  }

  explicit OverlayComponent(Context& context) : Component(context) {
    camera_ = calibration::load_camera_file(settings_.camera);
    snapshot_period_ = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(settings_.snapshot_period_s));
    if (!settings_.snapshot_directory.empty()) {
      std::filesystem::create_directories(settings_.snapshot_directory);
    }
    publisher_ = create_publisher<sensor_msgs::msg::Image>(topics::kOverlay);
    create_subscription<sensor_msgs::msg::Image>(
        topics::kCameraImage, [this](const std::shared_ptr<const sensor_msgs::msg::Image>& image) {
          if (Pending* pending = frame(to_nanoseconds(image->header().stamp()))) {
            pending->image = image;
          }
        });
    create_subscription<mocap_msgs::msg::FiducialArray>(
        topics::kFiducials, [this](const mocap_msgs::msg::FiducialArray& array) {
          Pending* pending = frame(to_nanoseconds(array.header().stamp()));
          if (pending == nullptr) return;
          for (const auto& f : array.fiducials()) {
            pending->content.fiducials.emplace_back(f.x(), f.y());
          }
        });
    create_subscription<mocap_msgs::msg::ConstellationArray>(
        topics::kConstellations, [this](const mocap_msgs::msg::ConstellationArray& array) {
          Pending* pending = frame(to_nanoseconds(array.header().stamp()));
          if (pending == nullptr) return;
          for (const auto& c : array.constellations()) {
            OverlayConstellation constellation{c.name(), {}};
            for (const auto& sub : c.sub_constellations()) {
              const auto& f = sub.fiducial_array().fiducials();
              if (f.size() != 4) continue;
              OverlayLine line{sub.name(), {}};
              for (int k = 0; k < 4; ++k) line.pixels[k] = {f[k].x(), f[k].y()};
              constellation.lines.push_back(line);
            }
            pending->content.constellations.push_back(std::move(constellation));
          }
        });
    create_subscription<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kPoses,
        [this](const mocap_msgs::msg::ConstellationPoseArray& poses) { draw(poses); });
  }

 private:
  struct Pending {
    std::shared_ptr<const sensor_msgs::msg::Image> image;
    OverlayFrame content;
  };

  // The frame stamped `stamp`, created if new; the oldest are forgotten beyond
  // kPendingFrames. Null for a stamp older than all of a full set: that frame was forgotten
  // already (its part came late), and creating it would only forget it again at once.
  Pending* frame(int64_t stamp) {
    if (auto found = frames_.find(stamp); found != frames_.end()) return &found->second;
    if (frames_.size() >= kPendingFrames && stamp < frames_.begin()->first) return nullptr;
    Pending& pending = frames_[stamp];
    while (frames_.size() > kPendingFrames) frames_.erase(frames_.begin());
    return &pending;
  }

  void draw(const mocap_msgs::msg::ConstellationPoseArray& poses) {
    auto found = frames_.find(to_nanoseconds(poses.header().stamp()));
    if (found == frames_.end() || !found->second.image) return;
    Pending pending = std::move(found->second);
    frames_.erase(frames_.begin(), std::next(found));
    Mono8View view = view_mono8(*pending.image);
    if (!view.problem.empty()) return;  // the tracker reports bad images
    for (const auto& p : poses.poses()) {
      if (std::optional<Eigen::Isometry3d> pose = to_isometry(p.pose().pose())) {
        pending.content.poses.push_back({p.name(), *pose});
      }
    }
    cv::Mat picture = draw_overlay(view.pixels, pending.content, camera_.model.get());
    auto message = std::make_shared<sensor_msgs::msg::Image>();
    message->header(poses.header());
    message->width(static_cast<uint32_t>(picture.cols));
    message->height(static_cast<uint32_t>(picture.rows));
    message->encoding("bgr8");
    message->step(static_cast<uint32_t>(picture.cols * 3));
    message->data().assign(picture.datastart, picture.dataend);
    publisher_.publish(std::move(message));
    save_snapshot(picture);
  }

  void save_snapshot(const cv::Mat& picture) {
    if (settings_.snapshot_directory.empty()) return;
    Clock::time_point t = now();
    if (snapshots_ > 0 && t - last_snapshot_ < snapshot_period_) return;
    last_snapshot_ = t;
    std::string path =
        fmt::format("{}/overlay_{:05d}.png", settings_.snapshot_directory, snapshots_++);
    if (std::string error = write_png(path, picture); !error.empty()) log().warn("{}", error);
  }

  calibration::CameraFile camera_;
  Clock::duration snapshot_period_{};
  Clock::time_point last_snapshot_{};
  int snapshots_ = 0;
  std::map<int64_t, Pending> frames_;
  Publisher<sensor_msgs::msg::Image> publisher_;
};

}  // namespace
}  // namespace mocap::overlay

MOCAP_REGISTER_COMPONENT(mocap::overlay::OverlayComponent, "overlay")
