// follower_monitor: the follower demo's live summary and final figures (follower_monitor.hpp)
// from the simulation's ground truth: pointing error of the turret, distance the base keeps,
// time from a lost track to a stopped base, and the rates of the loops.
#include <chrono>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <string>

#include <geometry_msgs/msg/pose_stamped.hpp>
#include <geometry_msgs/msg/twist.hpp>
#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <sensor_msgs/msg/joint_state.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "follower/follower_monitor/follower_monitor.hpp"

namespace mocap::evaluation {
namespace {

using geometry_msgs::msg::PoseStamped;
using mocap_msgs::msg::ConstellationPoseArray;

// The camera's poses come at the simulated base's 100 Hz: a second of them.
constexpr size_t kKeptCameraPoses = 100;
// A board showing this many of its markers can be tracked (three sides of twelve).
constexpr uint32_t kTrackableMarkers = 10;

int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Messages per second of one topic over a reporting period and over the run.
struct RateCounter {
  uint64_t total = 0, period = 0;
  int64_t first_ns = 0, last_ns = 0;
  void add(int64_t now_ns) {
    if (total++ == 0) first_ns = now_ns;
    last_ns = now_ns;
    ++period;
  }
  double overall_hz() const {
    return total > 1
               ? static_cast<double>(total - 1) / (static_cast<double>(last_ns - first_ns) * 1e-9)
               : 0.0;
  }
};

// The evaluation's options with what only the plugin reads.
struct Settings : FollowEvaluationOptions {
  std::string constellation = "board_a";
  double report_period_s = 2;
  std::string summary_file;  // empty: none
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("constellation", "the followed constellation", &Settings::constellation)
        .add("report_period_s", "seconds between summary lines", &Settings::report_period_s)
        .range(0.1, 3600)
        .add("settle_s", "the object standing this long: the base's distance counts as steady",
             &Settings::settle_s)
        .range(0, 3600)
        .add("summary_file", "where the final figures go (YAML), optional", &Settings::summary_file)
        .path();

class FollowerMonitor final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Follower demo figures from the simulation's ground truth: the turret's pointing "
        "error, the distance the base keeps from the object once it stands still, the time "
        "from a lost track to a stopped base, and loop rates; a live line and a final table.");
    kParameters.declare(spec);
    spec.subscribes<ConstellationPoseArray>(topics::kGroundTruth, Qos::reliable(),
                                            "the synthetic camera's ground truth");
    spec.subscribes<PoseStamped>(topics::kSimCameraPose, Qos::reliable(),
                                 "the camera in the world");
    spec.subscribes<PoseStamped>(topics::kBasePose, Qos::reliable(), "the base in the world");
    spec.subscribes<ConstellationPoseArray>(topics::kPoses, Qos::reliable(), "tracked poses");
    spec.subscribes<geometry_msgs::msg::Twist>(topics::kCmdVel, Qos::reliable(),
                                               "the drive follower's commands");
    spec.subscribes<sensor_msgs::msg::JointState>(topics::kTurretJointStates, Qos::reliable(),
                                                  "the turret's joint states (its cycle rate)");
    spec.subscribes<mocap_msgs::msg::Alert>(topics::kAlerts, Qos::reliable(), "alerts, counted");
  }

  explicit FollowerMonitor(Context& context) : Component(context) {
    evaluator_ = FollowEvaluator(settings_);
    create_subscription<PoseStamped>(topics::kSimCameraPose, [this](const PoseStamped& pose) {
      const std::optional<Eigen::Isometry3d> world_from_camera = to_isometry(pose.pose());
      if (!world_from_camera) return;
      camera_poses_.emplace_back(to_nanoseconds(pose.header().stamp()), *world_from_camera);
      while (camera_poses_.size() > kKeptCameraPoses) camera_poses_.pop_front();
    });
    create_subscription<PoseStamped>(topics::kBasePose, [this](const PoseStamped& pose) {
      evaluator_.add_base({pose.pose().position().x(), pose.pose().position().y()});
    });
    create_subscription<ConstellationPoseArray>(
        topics::kGroundTruth, [this](const ConstellationPoseArray& truth) {
          rates_["camera"].add(steady_ns());
          const std::optional<Eigen::Isometry3d> world_from_camera =
              camera_pose_at(to_nanoseconds(truth.header().stamp()));
          if (!world_from_camera) return;
          for (const auto& pose : truth.poses()) {
            if (pose.name() != settings_.constellation) continue;
            const auto& p = pose.pose().pose().position();
            evaluator_.add_truth(to_nanoseconds(pose.pose().header().stamp()),
                                 Eigen::Vector3d(p.x(), p.y(), p.z()), *world_from_camera,
                                 pose.points_used() >= kTrackableMarkers);
          }
        });
    create_subscription<ConstellationPoseArray>(topics::kPoses,
                                                [this](const ConstellationPoseArray& poses) {
                                                  for (const auto& pose : poses.poses()) {
                                                    if (pose.name() != settings_.constellation)
                                                      continue;
                                                    const int64_t now = steady_ns();
                                                    evaluator_.add_pose(now);
                                                    rates_["poses"].add(now);
                                                  }
                                                });
    create_subscription<geometry_msgs::msg::Twist>(
        topics::kCmdVel, [this](const geometry_msgs::msg::Twist& twist) {
          const int64_t now = steady_ns();
          rates_["drive"].add(now);
          evaluator_.add_velocity_command(now, twist.linear().x(), twist.angular().z());
        });
    create_subscription<sensor_msgs::msg::JointState>(
        topics::kTurretJointStates,
        [this](const sensor_msgs::msg::JointState&) { rates_["turret"].add(steady_ns()); });
    create_subscription<mocap_msgs::msg::Alert>(
        topics::kAlerts, [this](const mocap_msgs::msg::Alert&) { ++alerts_; });
    const double period_s = settings_.report_period_s;
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(period_s)),
                 [this, period_s] { report(period_s); });
  }

  ~FollowerMonitor() override {
    const FollowFigures& f = evaluator_.figures();
    const Spread pointing = spread(f.pointing_error_deg);
    const Spread walking = spread(f.pointing_error_walking_deg);
    const Spread distance = spread(f.steady_distance_m);
    const Spread stop = spread(f.stop_latency_s);
    size_t within = 0;
    for (double d : f.steady_distance_m) within += std::abs(d - 1.5) <= 0.1 ? 1 : 0;
    const double within_percent =
        f.steady_distance_m.empty() ? NAN : 100.0 * within / f.steady_distance_m.size();
    log().info("| figure | frames or events | median | p95 | max |");
    log().info("|---|---:|---:|---:|---:|");
    log().info("| pointing error, deg | {} | {:.2f} | {:.2f} | {:.2f} |",
               f.pointing_error_deg.size(), pointing.median, pointing.p95, pointing.max);
    log().info("| pointing error while walking, deg | {} | {:.2f} | {:.2f} | {:.2f} |",
               f.pointing_error_walking_deg.size(), walking.median, walking.p95, walking.max);
    log().info(
        "| distance kept, standing, m ({:.0f} % within 1.5 ± 0.1) | {} | {:.3f} | {:.3f} "
        "| {:.3f} |",
        within_percent, f.steady_distance_m.size(), distance.median, distance.p95, distance.max);
    log().info("| lost track -> zero velocity, s | {} | {:.3f} | {:.3f} | {:.3f} |",
               f.stop_latency_s.size(), stop.median, stop.p95, stop.max);
    log().info(
        "rates over the run: camera {:.1f} Hz, poses {:.1f} Hz, turret {:.1f} Hz, drive "
        "{:.1f} Hz; {} alerts",
        rates_["camera"].overall_hz(), rates_["poses"].overall_hz(), rates_["turret"].overall_hz(),
        rates_["drive"].overall_hz(), alerts_);
    write_summary(pointing, walking, distance, within_percent, stop);
  }

 private:
  // The camera pose the synthetic camera rendered a frame stamped `stamp_ns` with: the newest
  // published before it (the camera stamps a frame when it renders it, with the latest pose).
  std::optional<Eigen::Isometry3d> camera_pose_at(int64_t stamp_ns) const {
    for (auto pose = camera_poses_.rbegin(); pose != camera_poses_.rend(); ++pose) {
      if (pose->first <= stamp_ns) return pose->second;
    }
    return std::nullopt;
  }

  void report(double period_s) {
    const FollowFigures& f = evaluator_.figures();
    auto recent = [](const std::vector<double>& values, size_t since) {
      return spread(std::vector<double>(values.begin() + static_cast<long>(since), values.end()));
    };
    const Spread pointing = recent(f.pointing_error_deg, reported_pointing_);
    reported_pointing_ = f.pointing_error_deg.size();
    auto hz = [&](const char* topic) {
      RateCounter& counter = rates_[topic];
      const double rate = static_cast<double>(counter.period) / period_s;
      counter.period = 0;
      return rate;
    };
    log().info(
        "pointing error {:.2f} deg median, {:.2f} max; object {:.2f} m/s; distance kept {}; "
        "rates: camera {:.0f}, poses {:.0f}, turret {:.0f}, drive {:.0f} Hz; {} alerts",
        pointing.median, pointing.max, evaluator_.object_speed_mps(),
        f.steady_distance_m.empty() ? std::string("(not standing yet)")
                                    : fmt::format("{:.3f} m", f.steady_distance_m.back()),
        hz("camera"), hz("poses"), hz("turret"), hz("drive"), alerts_);
  }

  void write_summary(const Spread& pointing, const Spread& walking, const Spread& distance,
                     double within_percent, const Spread& stop) {
    if (settings_.summary_file.empty()) return;
    std::ofstream out(settings_.summary_file);
    out << fmt::format(
        "pointing_error_deg: {{median: {:.4f}, p95: {:.4f}, max: {:.4f}}}\n"
        "pointing_error_walking_deg: {{median: {:.4f}, p95: {:.4f}, max: {:.4f}}}\n"
        "steady_distance_m: {{median: {:.4f}, p95: {:.4f}, max: {:.4f}, within_percent: {:.1f}}}\n"
        "stop_latency_s: {{count: {}, median: {:.4f}, max: {:.4f}}}\n"
        "rates_hz: {{camera: {:.2f}, poses: {:.2f}, turret: {:.2f}, drive: {:.2f}}}\n"
        "alerts: {}\n",
        pointing.median, pointing.p95, pointing.max, walking.median, walking.p95, walking.max,
        distance.median, distance.p95, distance.max, within_percent,
        evaluator_.figures().stop_latency_s.size(), stop.median, stop.max,
        rates_["camera"].overall_hz(), rates_["poses"].overall_hz(), rates_["turret"].overall_hz(),
        rates_["drive"].overall_hz(), alerts_);
    if (!out) log().error("cannot write {}", settings_.summary_file);
  }

  FollowEvaluator evaluator_;
  std::deque<std::pair<int64_t, Eigen::Isometry3d>> camera_poses_;  // stamp, pose; oldest first
  std::map<std::string, RateCounter> rates_;
  size_t reported_pointing_ = 0;
  uint64_t alerts_ = 0;
};

}  // namespace
}  // namespace mocap::evaluation

MOCAP_REGISTER_COMPONENT(mocap::evaluation::FollowerMonitor, "follower_monitor")
