// pose_filter: /mocap/poses (the tracking pipeline's) -> /mocap/filtered_poses, each
// constellation's pose smoothed (pose_smoother.hpp), in this package's own message type.
#include <memory>

#include <geometry_msgs/msg/pose.hpp>
#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <pose_filter_msgs/msg/filtered_pose_array.hpp>

#include "pose_smoother.hpp"

namespace pose_filter {
namespace {

constexpr const char* kInput = "/mocap/poses";
constexpr const char* kOutput = "/mocap/filtered_poses";

Eigen::Isometry3d to_isometry(const geometry_msgs::msg::Pose& pose) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translate(Eigen::Vector3d(pose.position().x(), pose.position().y(), pose.position().z()));
  out.rotate(Eigen::Quaterniond(pose.orientation().w(), pose.orientation().x(),
                                pose.orientation().y(), pose.orientation().z())
                 .normalized());
  return out;
}

geometry_msgs::msg::Pose to_pose(const Eigen::Isometry3d& isometry) {
  geometry_msgs::msg::Pose out;
  const Eigen::Vector3d p = isometry.translation();
  const Eigen::Quaterniond q(isometry.rotation());
  out.position().x(p.x());
  out.position().y(p.y());
  out.position().z(p.z());
  out.orientation().x(q.x());
  out.orientation().y(q.y());
  out.orientation().z(q.z());
  out.orientation().w(q.w());
  return out;
}

// The smoother's options are the component's settings: each parameter below names its member,
// whose initial value in pose_smoother.hpp is the default.
const mocap::ParameterList<PoseSmootherOptions> kParameters =
    mocap::ParameterList<PoseSmootherOptions>()
        .add("position_smoothing", "weight of a new position, 0..1 (1: none)",
             &PoseSmootherOptions::position_smoothing)
        .range(0.01, 1)
        .add("orientation_smoothing", "weight of a new orientation, 0..1 (1: none)",
             &PoseSmootherOptions::orientation_smoothing)
        .range(0.01, 1)
        .add("restart_after_s", "a track unseen this long starts again",
             &PoseSmootherOptions::restart_after_s)
        .range(0, 60);

class PoseFilterComponent final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.description("Smooths each constellation's pose exponentially (position and orientation).");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::ConstellationPoseArray>(kInput, mocap::Qos::reliable(),
                                                             "estimated poses");
    spec.publishes<pose_filter_msgs::msg::FilteredPoseArray>(
        kOutput, mocap::Qos::reliable(), "smoothed poses, one array per input array");
  }

  explicit PoseFilterComponent(mocap::Context& context) : Component(context) {
    smoother_ = PoseSmoother(read_settings(kParameters));
    publisher_ = create_publisher<pose_filter_msgs::msg::FilteredPoseArray>(kOutput);
    create_subscription<mocap_msgs::msg::ConstellationPoseArray>(
        kInput, [this](const mocap_msgs::msg::ConstellationPoseArray& poses) { filter(poses); });
  }

  ~PoseFilterComponent() override { log().info("{} arrays filtered", arrays_); }

 private:
  void filter(const mocap_msgs::msg::ConstellationPoseArray& poses) {
    const double time_s = 1e-9 * static_cast<double>(mocap::to_nanoseconds(poses.header().stamp()));
    auto out = std::make_shared<pose_filter_msgs::msg::FilteredPoseArray>();
    out->header(poses.header());
    for (const auto& pose : poses.poses()) {
      const SmoothedPose smoothed =
          smoother_.update(pose.name(), time_s, to_isometry(pose.pose().pose()));
      pose_filter_msgs::msg::FilteredPose filtered;
      filtered.name(pose.name());
      filtered.pose(to_pose(smoothed.pose));
      filtered.raw(pose.pose().pose());
      filtered.smoothing()[0] = smoother_.options().position_smoothing;
      filtered.smoothing()[1] = smoother_.options().orientation_smoothing;
      filtered.samples(smoothed.samples);
      out->poses().push_back(std::move(filtered));
      if (smoothed.restarted) out->restarted().push_back(pose.name());
    }
    ++arrays_;
    publisher_.publish(std::move(out));
  }

  PoseSmoother smoother_;
  mocap::Publisher<pose_filter_msgs::msg::FilteredPoseArray> publisher_;
  unsigned long arrays_ = 0;
};

}  // namespace
}  // namespace pose_filter

MOCAP_REGISTER_COMPONENT(pose_filter::PoseFilterComponent, "pose_filter")
