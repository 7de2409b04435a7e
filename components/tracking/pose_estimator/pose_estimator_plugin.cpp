// pose_estimator: ConstellationArray -> ConstellationPoseArray (planar_pose.hpp).
#include <chrono>
#include <memory>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/database_parameters.hpp"
#include "tracking/pose_estimator/constellation_pose.hpp"
#include "tracking/pose_estimator/planar_pose.hpp"

namespace mocap::pose {
namespace {

// The estimator's options with the files only the plugin reads. min_points is 6 here: the
// identifier's lines come whole, four collinear points each, and one line alone leaves the
// board free to turn about it, so a pose needs a second line's points (the tracker, whose
// one-line identifications add loose markers off the line, keeps the estimator's 4).
struct Settings : PlanarPoseOptions {
  Settings() { min_points = 6; }
  constellations::DatabaseFiles boards;
  std::string camera = mocap::config_file("cameras/synthetic_ir_1280x720.yaml");
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .include(&Settings::boards, constellations::database_parameters())
        .add("camera", "camera file (ROS camera_info YAML)", &Settings::camera)
        .path()
        .add("max_reprojection_rms_px", "poses with a larger RMS reprojection error are rejected",
             &Settings::max_reprojection_rms_px)
        .range(0.01, 1000)
        .add("min_points", "fewest identified points for a pose", &Settings::min_points)
        .range(4, 1000);

class PoseEstimatorComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Estimates each identified constellation's 6-DoF pose in the camera frame (planar PnP "
        "and refinement) and rejects false identifications by their reprojection error.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::ConstellationArray>(topics::kConstellations, Qos::reliable(),
                                                         "identified constellations");
    spec.publishes<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kPoses, Qos::reliable(),
        "one stamped pose per accepted constellation, in the camera's frame");
  }

  explicit PoseEstimatorComponent(Context& context)
      : Component(context),
        database_(settings_.boards.load()),
        camera_(calibration::load_camera_file(settings_.camera)) {
    publisher_ = create_publisher<mocap_msgs::msg::ConstellationPoseArray>(topics::kPoses);
    create_subscription<mocap_msgs::msg::ConstellationArray>(
        topics::kConstellations,
        [this](const mocap_msgs::msg::ConstellationArray& array) { estimate(array); });
  }

  ~PoseEstimatorComponent() override {
    log().info("{} poses published, {} rejected", published_, rejected_);
  }

 private:
  void estimate(const mocap_msgs::msg::ConstellationArray& array) {
    auto message = std::make_shared<mocap_msgs::msg::ConstellationPoseArray>();
    message->header(array.header());
    if (message->header().frame_id().empty()) message->header().frame_id(camera_.frame_id);
    for (const auto& constellation : array.constellations()) {
      const auto* model = database_.find(constellation.name());
      if (model == nullptr) {
        reject(constellation.name(), "not in the database");
        continue;
      }
      std::vector<ObservedLine> lines;
      bool complete = true;
      for (const auto& sub : constellation.sub_constellations()) {
        const auto& fiducials = sub.fiducial_array().fiducials();
        if (fiducials.size() != 4) {
          complete = false;
          continue;
        }
        ObservedLine line{sub.name(), {}};
        for (int k = 0; k < 4; ++k) line.pixels[k] = {fiducials[k].x(), fiducials[k].y()};
        lines.push_back(line);
      }
      if (!complete) log().warn("{}: a line without 4 fiducials was skipped", constellation.name());
      Correspondences pairs = match_to_model(*model, lines);
      if (!pairs.unknown_lines.empty()) {
        reject(constellation.name(), fmt::format("lines {} are not in the database",
                                                 fmt::join(pairs.unknown_lines, ", ")));
        continue;
      }
      PlanarPose pose =
          estimate_planar_pose(*camera_.model, pairs.object_points, pairs.pixels, settings_);
      if (!pose.valid) {
        reject(constellation.name(), pose.rejection);
        continue;
      }
      message->poses().push_back(to_message(constellation.name(), message->header(), pose));
      ++published_;
    }
    publisher_.publish(std::move(message));
  }

  static mocap_msgs::msg::ConstellationPose to_message(const std::string& name,
                                                       const std_msgs::msg::Header& header,
                                                       const PlanarPose& pose) {
    mocap_msgs::msg::ConstellationPose out;
    out.name(name);
    out.pose().header(header);
    out.pose().pose(to_pose_message(pose.camera_from_object));
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) out.covariance()[6 * i + j] = pose.covariance(i, j);
    }
    out.reprojection_rms_px(static_cast<float>(pose.reprojection_rms_px));
    out.points_used(static_cast<uint32_t>(pose.points_used));
    out.cameras_used(1);
    return out;
  }

  void reject(const std::string& name, const std::string& why) {
    ++rejected_;
    Clock::time_point t = now();
    if (t - last_rejection_log_ >= std::chrono::seconds(1)) {
      log().info("rejected '{}': {} ({} rejections so far)", name, why, rejected_);
      last_rejection_log_ = t;
    }
  }

  constellations::ConstellationDatabase database_;
  calibration::CameraFile camera_;
  Publisher<mocap_msgs::msg::ConstellationPoseArray> publisher_;
  uint64_t published_ = 0, rejected_ = 0;
  Clock::time_point last_rejection_log_{};
};

}  // namespace
}  // namespace mocap::pose

MOCAP_REGISTER_COMPONENT(mocap::pose::PoseEstimatorComponent, "pose_estimator")
