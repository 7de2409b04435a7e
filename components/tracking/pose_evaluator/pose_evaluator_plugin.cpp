// pose_evaluator: compares /mocap/poses with the synthetic camera's ground truth and prints
// a live summary line and a final table (pose_evaluator.hpp).
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>

#include <mocap/component.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/pose_evaluator/pose_evaluator.hpp"

namespace mocap::evaluation {
namespace {

// An orientation variance this large (rad², on each axis) says the orientation is unknown: a
// robot of one marker has 1e9 there, as ROS's Odometry readers expect.
constexpr double kUnknownOrientationVariance = 1e6;

// `truth`: the synthetic camera's, whose velocities are exact (and have no covariance).
std::vector<ObjectPose> objects(const mocap_msgs::msg::ConstellationPoseArray& array, bool truth) {
  std::vector<ObjectPose> out;
  for (const auto& pose : array.poses()) {
    const std::optional<Eigen::Isometry3d> isometry = to_isometry(pose.pose().pose());
    if (!isometry) continue;  // no pose at all: as if not reported
    ObjectPose object;
    object.name = pose.name();
    object.pose = *isometry;
    object.visible_markers = static_cast<int>(pose.points_used());
    const auto& covariance = pose.covariance();
    object.orientation_known = truth || !(covariance[21] >= kUnknownOrientationVariance &&
                                          covariance[28] >= kUnknownOrientationVariance &&
                                          covariance[35] >= kUnknownOrientationVariance);
    // An estimate's velocity counts once measured: its covariance not all zeros ("unknown",
    // as the per-frame pose estimator leaves it) and its standard deviation below 0.5 m/s (a
    // track just started has the tracker's initial 2 m/s).
    const auto& c = pose.velocity_covariance();
    const double variance = c[0] + c[7] + c[14];
    if (truth || (variance > 0 && variance < 3 * 0.5 * 0.5)) {
      const auto& v = pose.velocity().linear();
      const auto& w = pose.velocity().angular();
      object.linear_velocity = Eigen::Vector3d(v.x(), v.y(), v.z());
      object.angular_velocity = Eigen::Vector3d(w.x(), w.y(), w.z());
    }
    out.push_back(std::move(object));
  }
  return out;
}

// The evaluation's options with what only the plugin reads.
struct Settings : EvaluationOptions {
  double report_period_s = 1;
  uint64_t stop_after_frames = 0;  // 0: never
  double skip_first_s = 0;
  std::string summary_file;  // empty: none
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("report_period_s", "seconds between summary lines", &Settings::report_period_s)
        .range(0.1, 3600)
        .add("min_visible_markers",
             "a truth object with fewer visible markers is not expected to be tracked",
             &Settings::min_visible_markers)
        .range(0, 10000)
        .add("stop_after_frames", "stop the process after evaluating this many frames (0: never)",
             &Settings::stop_after_frames)
        .range(0, 1e9)
        .add("skip_first_s",
             "seconds from the first truth array left out of the figures: the time a tracker "
             "takes to find the bodies, measured apart",
             &Settings::skip_first_s)
        .range(0, 3600)
        .add("summary_file", "where the final figures go (YAML), optional", &Settings::summary_file)
        .path()
        .add("max_lag_frames",
             "a frame whose estimate is this many truth frames late counts as lost (a test that "
             "must not depend on the machine's speed sets it high)",
             &Settings::max_pending_frames)
        .range(1, 1e7);

class PoseEvaluatorComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Compares estimated poses with the synthetic ground truth: a live summary line (input "
        "rate, latency, tracked %, errors) and a final table.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::ConstellationPoseArray>(topics::kGroundTruth, Qos::reliable(),
                                                             "ground truth, one array per image");
    spec.subscribes<mocap_msgs::msg::ConstellationPoseArray>(topics::kPoses, Qos::reliable(),
                                                             "estimated poses");
  }

  explicit PoseEvaluatorComponent(Context& context) : Component(context) {
    evaluator_ = PoseEvaluator(settings_);
    create_subscription<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kGroundTruth, [this](const mocap_msgs::msg::ConstellationPoseArray& truth) {
          // Once stopping, frames still in flight are not counted: the summary covers
          // stop_after_frames frames however long the stop takes.
          if (stopping_) return;
          const int64_t stamp_ns = to_nanoseconds(truth.header().stamp());
          if (!first_truth_ns_) first_truth_ns_ = stamp_ns;
          if (skipped(stamp_ns)) return;
          ++truth_arrays_;
          evaluator_.add_truth(stamp_ns, objects(truth, true));
          check_done();
        });
    create_subscription<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kPoses, [this](const mocap_msgs::msg::ConstellationPoseArray& poses) {
          if (stopping_ || skipped(to_nanoseconds(poses.header().stamp()))) return;
          const auto latency = now() - from_time_msg(poses.header().stamp());
          latencies_s_.push_back(std::chrono::duration<double>(latency).count());
          latency_.add(latency);
          evaluator_.add_estimate(to_nanoseconds(poses.header().stamp()), objects(poses, false),
                                  poses.cameras_late() > 0);
          check_done();
        });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.report_period_s)),
                 [this] { report(); });
  }

  ~PoseEvaluatorComponent() override { finish(); }

  void report_health(HealthReport& report) override {
    latency_.report(report, "capture -> poses received");
    const EvaluationSummary& total = evaluator_.total();
    report.add("frames evaluated", std::to_string(total.frames));
    report.add("tracked (%)",
               total.frames > 0 ? fmt::format("{:.2f}", total.tracked_percent()) : "-");
    report.add("false identifications", std::to_string(total.false_identifications));
    report.add("identity swaps", std::to_string(total.identity_swaps));
    if (total.false_identifications > 0 || total.identity_swaps > 0) {
      report.flag(HealthLevel::warn,
                  fmt::format("{} false identification(s), {} identity swap(s) against the truth",
                              total.false_identifications, total.identity_swaps));
    }
  }

 private:
  // In the first skip_first_s, or before the first truth array.
  bool skipped(int64_t stamp_ns) const {
    if (settings_.skip_first_s <= 0) return false;
    return !first_truth_ns_ ||
           static_cast<double>(stamp_ns - *first_truth_ns_) * 1e-9 < settings_.skip_first_s;
  }

  void report() {
    EvaluationSummary window = evaluator_.take_window();
    window_latencies_s_.swap(latencies_s_);
    all_latencies_s_.insert(all_latencies_s_.end(), window_latencies_s_.begin(),
                            window_latencies_s_.end());
    latencies_s_.clear();
    for (const FalseIdentification& f : window.false_identification_details) {
      if (std::isnan(f.position_error_m)) {
        log().warn("false identification: {} estimated at capture {} ns, not in view", f.name,
                   f.stamp_ns);
      } else {
        log().warn(
            "false identification: {} estimated at capture {} ns, {:.1f} mm and {:.2f} deg from "
            "the truth",
            f.name, f.stamp_ns, f.position_error_m * 1e3, f.orientation_error_deg);
      }
    }
    if (window.frames == 0) {
      log().info("no frames evaluated in the last {} s ({} truth arrays so far)",
                 settings_.report_period_s, truth_arrays_);
      return;
    }
    log().info(
        "{:.1f} frames/s, latency {:.2f} ms (p99 {:.2f} ms), {} frame(s) lost, tracked {:.1f} %, "
        "position error {:.2f} mm, orientation error {:.3f} deg, false identifications {}, "
        "identity swaps {}",
        window.frames / settings_.report_period_s,
        EvaluationSummary::quantile(window_latencies_s_, 0.5) * 1e3,
        EvaluationSummary::quantile(window_latencies_s_, 0.99) * 1e3, window.frames_lost,
        window.tracked_percent(), EvaluationSummary::quantile(window.position_errors_m, 0.5) * 1e3,
        EvaluationSummary::quantile(window.orientation_errors_deg, 0.5),
        window.false_identifications, window.identity_swaps);
  }

  void check_done() {
    if (settings_.stop_after_frames > 0 && !stopping_ &&
        evaluator_.total().frames >= settings_.stop_after_frames) {
      stopping_ = true;
      log().info("{} frames evaluated, stopping", evaluator_.total().frames);
      request_shutdown(0);
    }
  }

  void finish() {
    all_latencies_s_.insert(all_latencies_s_.end(), latencies_s_.begin(), latencies_s_.end());
    const EvaluationSummary& total = evaluator_.total();
    auto q = [](const std::vector<double>& v, double p) {
      return EvaluationSummary::quantile(v, p);
    };
    log().info(
        "| frames | lost | tracked | position mm (median, p95) | orientation deg "
        "(median, p95) | velocity error cm/s, deg/s (median) | false ids | latency ms (median, "
        "p99) | robots | identity swaps | frames short of a camera | tracked in the others |");
    log().info(
        "| {} | {} | {:.2f} % | {:.3f}, {:.3f} | {:.3f}, {:.3f} | {:.2f}, {:.2f} | {} | {:.2f}, "
        "{:.2f} | {} | {} | {} | {:.2f} % |",
        total.frames, total.frames_lost, total.tracked_percent(),
        q(total.position_errors_m, 0.5) * 1e3, q(total.position_errors_m, 0.95) * 1e3,
        q(total.orientation_errors_deg, 0.5), q(total.orientation_errors_deg, 0.95),
        q(total.velocity_errors_mps, 0.5) * 100, q(total.angular_velocity_errors_dps, 0.5),
        total.false_identifications, q(all_latencies_s_, 0.5) * 1e3,
        q(all_latencies_s_, 0.99) * 1e3, total.objects, total.identity_swaps,
        total.incomplete_frames, total.tracked_percent_in_complete_frames());
    if (settings_.summary_file.empty()) return;
    std::ofstream out(settings_.summary_file);
    out << "frames: " << total.frames << "\nframes_lost: " << total.frames_lost
        << "\nrobots: " << total.objects << "\nexpected: " << total.expected
        << "\ntracked: " << total.tracked << "\nincomplete_frames: " << total.incomplete_frames
        << "\nexpected_in_incomplete: " << total.expected_in_incomplete
        << "\ntracked_in_incomplete: " << total.tracked_in_incomplete
        << "\nfalse_identifications: " << total.false_identifications
        << "\nidentity_swaps: " << total.identity_swaps
        << "\nposition_error_median_m: " << q(total.position_errors_m, 0.5)
        << "\nposition_error_p95_m: " << q(total.position_errors_m, 0.95)
        << "\norientation_error_median_deg: " << q(total.orientation_errors_deg, 0.5)
        << "\norientation_error_p95_deg: " << q(total.orientation_errors_deg, 0.95)
        << "\nvelocity_errors: " << total.velocity_errors_mps.size()
        << "\nvelocity_error_median_mps: " << q(total.velocity_errors_mps, 0.5)
        << "\nangular_velocity_error_median_dps: " << q(total.angular_velocity_errors_dps, 0.5)
        << "\nlatency_median_s: " << q(all_latencies_s_, 0.5)
        << "\nlatency_p99_s: " << q(all_latencies_s_, 0.99) << "\n";
    if (!out) log().error("cannot write {}", settings_.summary_file);
  }

  PoseEvaluator evaluator_;
  bool stopping_ = false;
  uint64_t truth_arrays_ = 0;
  std::optional<int64_t> first_truth_ns_;  // the first truth array's stamp
  std::vector<double> latencies_s_, window_latencies_s_, all_latencies_s_;
  LatencyFigures latency_;
};

}  // namespace
}  // namespace mocap::evaluation

MOCAP_REGISTER_COMPONENT(mocap::evaluation::PoseEvaluatorComponent, "pose_evaluator")
