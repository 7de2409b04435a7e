// constellation_tracker: FiducialArray -> ConstellationArray + ConstellationPoseArray with
// velocities (constellation_tracker.hpp). The tracking stage of the shipped deployments: it
// keeps its tracks itself and needs nothing but the fiducials, in order.
#include <chrono>
#include <memory>
#include <optional>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/constellation_array.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "tracking/constellation_database/database_parameters.hpp"
#include "tracking/constellation_identifier/constellation_message.hpp"
#include "tracking/constellation_tracker/constellation_tracker.hpp"

namespace mocap::tracking {
namespace {

// The tracker's options with the files only the plugin reads.
struct Settings : TrackerOptions {
  constellations::DatabaseFiles boards;
  std::string camera = mocap::config_file("cameras/synthetic_ir_1280x720.yaml");
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .include(&Settings::boards, constellations::database_parameters())
        .add("camera", "camera file (ROS camera_info YAML, or one mocap_calibrate wrote)",
             &Settings::camera)
        .path()
        .add("cross_ratio_tolerance",
             "identification: largest relative cross-ratio difference (the seed used 0.20)",
             &Settings::identification, &constellations::IdentifierOptions::cross_ratio_tolerance)
        .range(1e-4, 0.5)
        .add("line_tolerance_px",
             "identification: largest distance of a point from its line, pixels",
             &Settings::identification, &constellations::IdentifierOptions::line_search,
             &constellations::LineSearchOptions::tolerance_px)
        .range(0.01, 100)
        .add("min_loose_markers",
             "identification from one whole line: loose markers that must confirm it; 0 = never "
             "identify from one line",
             &Settings::identification, &constellations::IdentifierOptions::min_loose_markers)
        .range(0, 1000)
        .add("max_reprojection_rms_px",
             "poses with a larger RMS reprojection error are not believed", &Settings::pose,
             &pose::PlanarPoseOptions::max_reprojection_rms_px)
        .range(0.01, 1000)
        .add("min_tracked_markers", "fewest markers that keep a tracked board",
             &Settings::min_tracked_markers)
        .range(4, 1000)
        .add("linear_acceleration_density",
             "motion model: white-noise acceleration, m^2/s^3 (larger follows faster changes of "
             "speed, with noisier velocities)",
             &Settings::motion, &BodyMotionOptions::linear_acceleration_density)
        .range(1e-6, 1e6)
        .add("angular_acceleration_density",
             "motion model: white-noise angular acceleration, rad^2/s^3", &Settings::motion,
             &BodyMotionOptions::angular_acceleration_density)
        .range(1e-6, 1e6);

class ConstellationTrackerComponent final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Follows constellations from frame to frame: predicts each tracked board at the "
        "frame's capture time, associates the fiducials with its markers, estimates the pose "
        "from any four or more of them and verifies it against the whole board; identifies "
        "the boards not tracked (also from one whole line and loose markers). Publishes the "
        "seed's constellations and each board's pose with its velocity.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::FiducialArray>(
        topics::kFiducials, Qos::reliable(), "fiducials of one image, pixels, stamped at capture");
    spec.publishes<mocap_msgs::msg::ConstellationArray>(
        topics::kConstellations, Qos::reliable(),
        "the boards found in each fiducial array: each line's fiducials in database order, NaN "
        "for a marker not seen");
    spec.publishes<mocap_msgs::msg::ConstellationPoseArray>(
        topics::kPoses, Qos::reliable(),
        "one pose per board found, in the camera's frame, with its velocity; stamped with the "
        "image's capture time");
  }

  explicit ConstellationTrackerComponent(Context& context)
      : Component(context),
        database_(settings_.boards.load()),
        camera_(calibration::load_camera_file(settings_.camera)) {
    for (const std::string& problem :
         database_.ambiguities(settings_.identification.cross_ratio_tolerance)) {
      log().warn("{}", problem);
    }
    tracker_.emplace(database_, camera_.model, settings_);
    log().info("{} constellations from {}", database_.constellations().size(),
               settings_.boards.database);
    constellations_ =
        create_publisher<mocap_msgs::msg::ConstellationArray>(topics::kConstellations);
    poses_ = create_publisher<mocap_msgs::msg::ConstellationPoseArray>(topics::kPoses);
    create_subscription<mocap_msgs::msg::FiducialArray>(
        topics::kFiducials, [this](const mocap_msgs::msg::FiducialArray& array) { track(array); });
  }

  ~ConstellationTrackerComponent() override {
    log().info(
        "{} arrays: {} poses ({} tracked, {} of them found again by the picture's shift; {} "
        "identified, {} of them from one line), {} not believed, {} tracks lost",
        arrays_, totals_.tracked + totals_.identified, totals_.tracked, totals_.relocked,
        totals_.identified, totals_.from_one_line, totals_.rejected, totals_.lost);
  }

 private:
  void track(const mocap_msgs::msg::FiducialArray& array) {
    ++arrays_;
    const auto& fiducials = array.fiducials();
    fiducials_.resize(fiducials.size());
    for (size_t i = 0; i < fiducials.size(); ++i) {
      fiducials_[i] = {Eigen::Vector2d(fiducials[i].x(), fiducials[i].y()), fiducials[i].size()};
    }
    TrackerStats stats;
    const auto found = tracker_->update(to_nanoseconds(array.header().stamp()), fiducials_, &stats);
    totals_.tracked += stats.tracked;
    totals_.relocked += stats.relocked;
    totals_.identified += stats.identified;
    totals_.from_one_line += stats.from_one_line;
    totals_.rejected += stats.rejected;
    totals_.lost += stats.lost;
    if (!stats.rejections.empty()) report(stats);

    auto constellations = std::make_shared<mocap_msgs::msg::ConstellationArray>();
    constellations->header(array.header());
    auto poses = std::make_shared<mocap_msgs::msg::ConstellationPoseArray>();
    poses->header(array.header());
    if (poses->header().frame_id().empty()) poses->header().frame_id(camera_.frame_id);
    for (const TrackedConstellation& board : found) {
      constellations->constellations().push_back(
          constellations::to_constellation_message(board.identified, array));
      poses->poses().push_back(to_message(board, poses->header()));
    }
    constellations_.publish(std::move(constellations));
    poses_.publish(std::move(poses));
  }

  static mocap_msgs::msg::ConstellationPose to_message(const TrackedConstellation& board,
                                                       const std_msgs::msg::Header& header) {
    mocap_msgs::msg::ConstellationPose out;
    out.name(board.identified.model->name);
    out.pose().header(header);
    out.pose().pose(to_pose_message(board.pose.camera_from_object));
    const Matrix6d velocity_covariance = board.motion.velocity_covariance();
    for (int i = 0; i < 6; ++i) {
      for (int j = 0; j < 6; ++j) {
        out.covariance()[6 * i + j] = board.pose.covariance(i, j);
        out.velocity_covariance()[6 * i + j] = velocity_covariance(i, j);
      }
    }
    out.reprojection_rms_px(static_cast<float>(board.pose.reprojection_rms_px));
    out.points_used(static_cast<uint32_t>(board.pose.points_used));
    out.cameras_used(1);
    out.velocity(to_twist_message(board.motion.linear_velocity, board.motion.angular_velocity));
    return out;
  }

  // At most one line a second, so a scene full of near misses cannot flood the log.
  void report(const TrackerStats& stats) {
    Clock::time_point t = now();
    if (t - last_report_ < std::chrono::seconds(1)) return;
    last_report_ = t;
    log().info("not believed or lost: {} ({} so far)", fmt::join(stats.rejections, "; "),
               totals_.rejected + totals_.lost);
  }

  constellations::ConstellationDatabase database_;
  calibration::CameraFile camera_;
  std::optional<ConstellationTracker> tracker_;
  Publisher<mocap_msgs::msg::ConstellationArray> constellations_;
  Publisher<mocap_msgs::msg::ConstellationPoseArray> poses_;
  std::vector<ImageFiducial> fiducials_;
  uint64_t arrays_ = 0;
  TrackerStats totals_;
  Clock::time_point last_report_{};
};

}  // namespace
}  // namespace mocap::tracking

MOCAP_REGISTER_COMPONENT(mocap::tracking::ConstellationTrackerComponent, "constellation_tracker")
