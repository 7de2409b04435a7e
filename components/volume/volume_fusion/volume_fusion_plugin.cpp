// volume_fusion: a volume's fixed cameras' fiducials -> one world pose per rigid body
// (volume_fusion.hpp), published on /mocap/poses in frame 'world' for each capture time.
//
// Each camera's fiducials come on its own topic (/volume/{camera}/fiducials, the name in its
// camera file), stamped at capture. The messages of one capture time are gathered
// (frame_assembler.hpp): a frame is fused when every live camera has given its message, or
// a frame period (as the capture times show it) after its first one, `wait_s` (30 ms) at most. A
// camera silent for `silent_after_s` is left out and reported on /alerts, and taken back, also
// reported, at its next message; so is a camera found drifted (its extrinsics moved: its residuals
// against the others' poses), and a body seen by one camera only (its pose then rests on that
// camera alone).
//
// Every fused frame's markers in 3D (the marker cloud: marker_cloud.hpp) go out on
// /mocap/markers as a PointCloud2 (marker_cloud_message.hpp), each labeled with the body or
// robot it belongs to. With a `robots` file, the swarm's robots (identical layouts told apart
// by their tracks, and robots of one marker: swarm_tracker.hpp) are tracked in the cloud's
// markers no body took, and posed on /mocap/poses after the bodies; /mocap/reseed tells where a
// robot carried away by hand now is.
//
// The cameras' hosts' clocks are measured against this one's (clock probes, answered by each
// process's diagnostics component: clock_offset.hpp): a camera whose clock is unknown or off by
// more than `clock_limit_ms` is refused, by name, until its clock is back within it; one off by
// more than `clock_warning_ms` is fused with a warning. Stamps of different clocks pair wrongly
// in the frames, and a camera stamping 5 ms off at 1 m/s puts its markers 5 mm away.
#include <algorithm>
#include <bit>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <mocap/calibration/camera_file.hpp>
#include <mocap/component.hpp>
#include <mocap/config_files.hpp>
#include <mocap/message_time.hpp>
#include <mocap_msgs/msg/alert.hpp>
#include <mocap_msgs/msg/clock_probe.hpp>
#include <mocap_msgs/msg/clock_probe_reply.hpp>
#include <mocap_msgs/msg/constellation_pose_array.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <motion_capture_tracking_interfaces/msg/named_pose_array.hpp>
#include <sensor_msgs/msg/point_cloud2.hpp>
#include <tf2_msgs/msg/tf_message.hpp>

#include "common/marker_cloud_message/marker_cloud_message.hpp"
#include "common/pose_message/pose_message.hpp"
#include "common/topics/graph_topics.hpp"
#include "health/clock_offset/clock_offset.hpp"
#include "volume/frame_assembly/frame_assembler.hpp"
#include "volume/marker_cloud/marker_cloud.hpp"
#include "volume/rigid_bodies/rigid_body_database.hpp"
#include "volume/swarm/swarm_database.hpp"
#include "volume/swarm/swarm_tracker.hpp"
#include "volume/volume_fusion/volume_fusion.hpp"

namespace mocap::volume {
namespace {

using mocap_msgs::msg::Alert;
using mocap_msgs::msg::ClockProbe;
using mocap_msgs::msg::ClockProbeReply;
using mocap_msgs::msg::ConstellationPoseArray;
using mocap_msgs::msg::FiducialArray;
using motion_capture_tracking_interfaces::msg::NamedPoseArray;
using sensor_msgs::msg::PointCloud2;
using tf2_msgs::msg::TFMessage;

constexpr std::chrono::milliseconds kSingleCameraAlert{500};
constexpr std::chrono::milliseconds kUnposedAlert{500};
constexpr size_t kMaxBacklog = 2;  // the newest frames fused at once when behind
// A camera that misses this many frames in a row is said to be back when it returns.
constexpr int kGapFramesLogged = 3;
// A cloud marker this close to where a posed body puts one of its markers is that marker.
constexpr double kOwnMarkerRadius_m = 0.005;
// A process that has not answered a clock probe for this long has ended.
constexpr std::chrono::seconds kClockSilence{3};
// A camera's clock is settled once an exchange with its host was this quick (it tells the
// offset to half of it, a tenth of a millisecond) or the exchanges span kSettlingSpan: its offset
// is logged, and where no exchange proved it within or beyond the limit, it is judged on the best.
constexpr std::chrono::nanoseconds kSettledRoundTrip{200'000};
// On a busy host a quick exchange is rare: the more probes in the second the design gives for a
// camera's clock to be known, the likelier one is (with 32 exchanges, 0.3 s, a busy run settled
// on a 0.38 ms round trip and an offset 0.13 ms off).
constexpr std::chrono::milliseconds kSettlingSpan{700};
// Probes come this often while a camera's clock is not settled.
constexpr std::chrono::milliseconds kSettlingProbePeriod{4};
// Messages held while their camera's clock is not known (hold()): at most this many, and a
// probe for them at most this often.
constexpr size_t kMaxHeld = 64;
constexpr std::chrono::milliseconds kHeldProbePeriod{1};

bool settled(const health::ClockOffset& offset) {
  return offset.round_trip_ns <= kSettledRoundTrip.count() ||
         offset.span_ns >= std::chrono::nanoseconds(kSettlingSpan).count();
}
// A camera whose clock stays unknown this long after its first message is said to be refused.
constexpr std::chrono::seconds kUnknownClockAlert{1};

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

// The tracker's options with what only the plugin reads.
struct Settings : VolumeTrackerOptions {
  std::vector<std::string> cameras = {mocap::config_file("volume/cameras/cam_0.yaml"),
                                      mocap::config_file("volume/cameras/cam_1.yaml"),
                                      mocap::config_file("volume/cameras/cam_2.yaml"),
                                      mocap::config_file("volume/cameras/cam_3.yaml")};
  std::string bodies = mocap::config_file("volume/bodies.yaml");
  std::string robots;  // none
  MarkerCloudOptions cloud;
  SwarmTrackerOptions swarm;
  double same_capture_s = 0.002;
  double wait_s = 0.03;
  double silent_after_s = 0.5;
  double behind_max_gap_s = 0.02;
  bool check_clocks = true;
  double clock_probe_hz = 20;
  double clock_warning_ms = 0.2;
  double clock_limit_ms = 1.0;

  // The shipped bodies are told apart by 5 markers (config/volume/bodies.yaml).
  Settings() { identification.min_markers = 5; }
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("cameras",
             "the volume's camera files, each with its `pose` in the world; the file's "
             "camera_name names the camera's topic",
             &Settings::cameras)
        .path()
        .add("bodies",
             "the rigid bodies, each of its own marker layout (rigid_body_database.hpp); empty: "
             "none",
             &Settings::bodies)
        .path()
        .add("robots",
             "the swarm: robots of shared marker layouts or of one marker, and where each "
             "starts (swarm_database.hpp); empty: none",
             &Settings::robots)
        .path()
        .add("marker_gate_px",
             "how far a detection may be from where a cloud marker's track predicts it",
             &Settings::cloud, &MarkerCloudOptions::gate_px)
        .range(0.1, 100)
        .add("marker_tolerance_px",
             "how far a cloud marker may reproject from a detection it explains", &Settings::cloud,
             &MarkerCloudOptions::tolerance_px)
        .range(0.01, 100)
        .add("marker_min_cameras", "fewest cameras that start a cloud marker", &Settings::cloud,
             &MarkerCloudOptions::min_cameras_to_start)
        .range(2, kMaxCloudCameras)
        .add("robot_gate_m",
             "how far a marker may be from where a tracked robot's motion puts one of its markers",
             &Settings::swarm, &SwarmTrackerOptions::gate_m)
        .range(1e-4, 1)
        .add("robot_start_radius_m",
             "how far from its initial (or re-seeded) position a robot is looked for",
             &Settings::swarm, &SwarmTrackerOptions::start_radius_m)
        .range(1e-3, 100)
        .add("robot_start_speed_mps",
             "a robot is found at its start only among markers not known to move faster than "
             "this: at rest",
             &Settings::swarm, &SwarmTrackerOptions::start_speed_mps)
        .range(1e-3, 100)
        .add("robot_lost_after_s",
             "a robot missed in every frame fused for this long is lost: looked for afresh",
             &Settings::swarm, &SwarmTrackerOptions::lost_after_s)
        .range(0, 3600)
        .add("body_tolerance_m",
             "how far a triangulated inter-marker distance may be from the body's",
             &Settings::identification, &RigidBodyIdentificationOptions::tolerance)
        .range(1e-4, 0.1)
        .add("min_markers", "fewest of a body's markers that identify it",
             &Settings::identification, &RigidBodyIdentificationOptions::min_markers)
        .range(3, 1000)
        .add("triangulation_tolerance_px",
             "how far a triangulated marker may reproject from a detection it explains",
             &Settings::triangulation, &MarkerTriangulationOptions::tolerance_px)
        .range(0.01, 100)
        .add("match_radius_px",
             "how far a detection may be from where a track predicts one of its markers",
             &Settings::match_radius_px)
        .range(0.1, 1000)
        .add("max_reprojection_rms_px", "a fused pose with a larger RMS is rejected",
             &Settings::fusion, &MultiCameraPoseOptions::max_reprojection_rms_px)
        .range(0.01, 100)
        .add("lost_after_s", "a track not fused for this long is dropped", &Settings::lost_after_s)
        .range(0, 3600)
        .add("drift_px",
             "a camera whose average residual against the fused poses exceeds this has "
             "moved: reported and left out",
             &Settings::drift_px)
        .range(0.01, 100)
        .add("same_capture_s", "stamps this close are one capture time", &Settings::same_capture_s)
        .range(0, 1)
        .add("wait_s",
             "how long a frame waits for late cameras after its first message, at most: the "
             "frame period when that is shorter",
             &Settings::wait_s)
        .range(0, 1)
        .add("silent_after_s", "a camera silent this long is left out until it returns",
             &Settings::silent_after_s)
        .range(0.001, 3600)
        .add("behind_max_gap_s",
             "a fusion that is behind skips frames, but fuses frames at most this far apart (or "
             "two frame periods): the tracks bridge the gap",
             &Settings::behind_max_gap_s)
        .range(0.001, 10)
        .add("check_clocks",
             "measure each camera's host's clock against this one's and refuse a camera whose "
             "clock is unknown or off by more than clock_limit_ms (false: for cameras in this "
             "process only, or a graph without diagnostics components)",
             &Settings::check_clocks)
        .add("clock_probe_hz",
             "clock probes a second once every camera's clock is settled (250 before)",
             &Settings::clock_probe_hz)
        .range(0.5, 100)
        .add("clock_warning_ms", "a camera's clock off by more than this is fused with a warning",
             &Settings::clock_warning_ms)
        .range(0, 1000)
        .add("clock_limit_ms",
             "a camera's clock off by more than this is refused: its stamps would pair with other "
             "capture times (same_capture_s) and move its markers",
             &Settings::clock_limit_ms)
        .range(0, 10000);

std::vector<VolumeCamera> load_cameras(const std::vector<std::string>& files) {
  if (files.empty()) throw std::invalid_argument("cameras: no camera files");
  std::vector<VolumeCamera> cameras;
  for (const std::string& file : files) {
    calibration::CameraFile camera = calibration::load_camera_file(file);
    if (!camera.world_from_camera) {
      throw std::invalid_argument(file +
                                  ": no `pose`: a volume camera needs its place in the world");
    }
    if (camera.name.empty()) throw std::invalid_argument(file + ": no camera_name");
    for (const VolumeCamera& other : cameras) {
      if (other.name == camera.name) {
        throw std::invalid_argument(file + ": camera_name '" + camera.name + "' is taken");
      }
    }
    cameras.push_back(
        {camera.name, camera.model, camera.world_from_camera->inverse(), camera.frame_id});
  }
  return cameras;
}

// The swarm of the `robots` file, or none; a robot named as a body is refused.
std::optional<SwarmTracker> load_robots(const Settings& settings, const RigidBodyDatabase& bodies) {
  if (settings.robots.empty()) return std::nullopt;
  SwarmDatabase swarm = load_swarm(settings.robots, settings.swarm.layout_tolerance_m);
  for (const SwarmRobot& robot : swarm.robots) {
    for (const RigidBody& body : bodies.bodies) {
      if (body.name == robot.name) {
        throw std::invalid_argument(
            fmt::format("{}: robot '{}' has the name of a body of {}: poses are told apart by name",
                        settings.robots, robot.name, settings.bodies));
      }
    }
  }
  return SwarmTracker(std::move(swarm), settings.swarm);
}

// A pose message of the array's header.
mocap_msgs::msg::ConstellationPose pose_message(const std_msgs::msg::Header& header,
                                                const std::string& name,
                                                const Eigen::Isometry3d& world_from_body,
                                                const Eigen::Matrix<double, 6, 6>& covariance) {
  mocap_msgs::msg::ConstellationPose pose;
  pose.name(name);
  pose.pose().header(header);
  pose.pose().pose(to_pose_message(world_from_body));
  for (int i = 0; i < 36; ++i) pose.covariance()[static_cast<size_t>(i)] = covariance(i / 6, i % 6);
  return pose;
}

void set_velocity(mocap_msgs::msg::ConstellationPose& pose, const Eigen::Vector3d& linear,
                  const Eigen::Vector3d& angular, const Eigen::Matrix<double, 6, 6>& covariance) {
  for (int i = 0; i < 36; ++i) {
    pose.velocity_covariance()[static_cast<size_t>(i)] = covariance(i / 6, i % 6);
  }
  pose.velocity(to_twist_message(linear, angular));
}

class VolumeFusion final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Fuses a volume of fixed, calibrated cameras: each camera's fiducials of one capture "
        "time gathered, markers triangulated, rigid bodies identified by their markers' "
        "distances and tracked, each body's world pose fitted over every camera that sees it "
        "(with covariance and velocity). Silent, returning and drifted cameras and bodies seen "
        "by one camera only go to /alerts.");
    kParameters.declare(spec);
    spec.subscribes<FiducialArray>(topics::kVolumeFiducials, Qos::sensor_data(),
                                   "one topic per camera: its fiducials in pixels, stamped at "
                                   "capture");
    spec.publishes<ConstellationPoseArray>(
        topics::kPoses, Qos::reliable(),
        "each body posed in a frame: frame 'world', stamped with the capture time; "
        "points_used counts pixels over every camera, cameras_used the cameras (1: a "
        "single camera's pose)");
    spec.publishes<PointCloud2>(
        topics::kMarkers, Qos::sensor_data(),
        "every fused frame's markers in 3D: frame 'world', stamped with the capture time; fields "
        "x y z, body (the index of its pose's name among the bodies then the robots; -1 "
        "unlabeled), marker, id (its track's), residual (px), cameras (a bit per camera)");
    spec.subscribes<NamedPoseArray>(topics::kReseed, Qos::reliable(),
                                    "robots carried away by hand: each looked for at its position");
    spec.publishes<Alert>(topics::kAlerts, Qos::reliable(),
                          "cameras silent, back or drifted; bodies seen by one camera only");
    spec.publishes<TFMessage>(
        topics::kTfStatic, Qos::latched(),
        "once: each camera's optical frame (its images' frame id) in 'world'");
    spec.publishes<ClockProbe>(topics::kClockProbe, Qos::sensor_data(),
                               "clock probes, clock_probe_hz a second (check_clocks)");
    // Best effort, as the answers are sent, but a queue for every process's answers to the
    // probes of a settling burst (250 a second).
    spec.subscribes<ClockProbeReply>(
        topics::kClockReply,
        {Reliability::BestEffort, Durability::Volatile, History::KeepLast, 256},
        "the processes' answers: the cameras' hosts' clocks");
  }

  explicit VolumeFusion(Context& context)
      : Component(context),
        tracker_(load_cameras(settings_.cameras),
                 settings_.bodies.empty()
                     ? RigidBodyDatabase{}
                     : load_rigid_bodies(settings_.bodies, settings_.identification.tolerance,
                                         settings_.identification.min_markers),
                 settings_),
        cloud_(settings_.cloud),
        swarm_(load_robots(settings_, tracker_.bodies())),
        frames_(static_cast<int>(tracker_.cameras().size()),
                {.same_capture = seconds(settings_.same_capture_s),
                 .wait = seconds(settings_.wait_s),
                 .silent_after = seconds(settings_.silent_after_s)}),
        heard_(tracker_.cameras().size(), false),
        silent_(tracker_.cameras().size(), false),
        gaps_(tracker_.cameras().size()),
        drifted_(tracker_.cameras().size(), false),
        clock_states_(tracker_.cameras().size()) {
    poses_ = create_publisher<ConstellationPoseArray>(topics::kPoses);
    markers_ = create_publisher<PointCloud2>(topics::kMarkers);
    alerts_ = create_publisher<Alert>(topics::kAlerts);
    create_subscription<NamedPoseArray>(topics::kReseed,
                                        [this](const NamedPoseArray& array) { reseed(array); });
    publish_camera_frames();
    for (size_t c = 0; c < tracker_.cameras().size(); ++c) {
      create_subscription<FiducialArray>(
          topics::member_of(topics::kVolumeFiducials, tracker_.cameras()[c].name),
          [this, c](const FiducialArray& array) {
            const auto arrival = std::chrono::steady_clock::now();
            release_held(arrival);
            switch (judge_clock(c, arrival)) {
              case ClockVerdict::accepted:
              case ClockVerdict::warned:
                return take_fiducials(c, array, arrival);
              case ClockVerdict::unknown:
                if (hold(c, array, arrival)) return;
                [[fallthrough]];
              case ClockVerdict::refused:
                ++clock_states_[c].refused;
            }
          });
    }
    if (settings_.check_clocks) {
      probes_ = create_publisher<ClockProbe>(topics::kClockProbe);
      create_subscription<ClockProbeReply>(
          topics::kClockReply, [this](const ClockProbeReply& reply) { take_clock_reply(reply); });
      create_timer(kSettlingProbePeriod, [this] { probe_clocks(); });
    }
    // Frames whose wait runs out while no message arrives: a camera that stopped.
    create_timer(std::chrono::milliseconds(1), [this] {
      release_held(std::chrono::steady_clock::now());
      fuse_ready();
    });
    std::string names;
    for (const VolumeCamera& camera : tracker_.cameras()) names += " " + camera.name;
    log().info("{} bodies ({}), {} robots ({}), {} cameras:{}", tracker_.bodies().bodies.size(),
               settings_.bodies.empty() ? "none" : settings_.bodies,
               swarm_ ? swarm_->swarm().robots.size() : 0,
               settings_.robots.empty() ? "none" : settings_.robots, tracker_.cameras().size(),
               names);
  }

  ~VolumeFusion() override {
    std::string health;
    for (size_t c = 0; c < tracker_.cameras().size(); ++c) {
      const CameraHealth& h = tracker_.camera_health()[c];
      health += fmt::format(
          "; {}: residual {:.2f} px over {} views, left out {}{}{}", tracker_.cameras()[c].name,
          h.average_error_px, h.views, h.left_out, h.drifted ? ", DRIFTED" : "",
          settings_.check_clocks
              ? fmt::format(", {} refused for its clock", clock_states_[c].refused)
              : "");
    }
    log().info(
        "{} frames fused ({} incomplete, {} skipped while behind), {} body poses ({} from one "
        "camera), {} robot poses, {} identifications, {} fits set aside as unusually poor, {} "
        "late messages dropped (a frame waited {:.2f} ms of its {:.2f}); marker cloud: {} tracks "
        "started, {} detections left out as merged, {} no marker explains{}",
        fused_frames_, incomplete_frames_, skipped_frames_, body_poses_, single_camera_poses_,
        robot_poses_, tracker_.identifications(), tracker_.unusual_fits(), frames_.late_drops(),
        std::chrono::duration<double, std::milli>(frames_.wait()).count(),
        std::chrono::duration<double, std::milli>(frames_.frame_period()).count(),
        cloud_.totals().started, cloud_.totals().merged, cloud_.totals().unexplained, health);
  }

  void report_health(HealthReport& report) override {
    const double period_s = std::chrono::duration<double>(frames_.frame_period()).count();
    report.add("fused frames", std::to_string(fused_frames_));
    report.add("camera frame rate (Hz)", period_s > 0 ? fmt::format("{:.1f}", 1 / period_s) : "-");
    if (period_s > 0) {
      fused_rate_.report(report, "fused frames", 1 / period_s,
                         "the fusion is behind its cameras and skips frames: the host is too "
                         "busy, or the scene too large for it");
    }
    report.add("incomplete frames", std::to_string(incomplete_frames_));
    report.add("skipped while behind", std::to_string(skipped_frames_));
    report.add("late messages dropped", std::to_string(frames_.late_drops()));
    arrival_latency_.report(report, "capture -> fiducials received");
    poses_latency_.report(report, "capture -> poses sent");
    for (size_t c = 0; c < tracker_.cameras().size(); ++c) {
      const std::string& camera = tracker_.cameras()[c].name;
      const ClockState& clock = clock_states_[c];
      if (settings_.check_clocks) {
        report.add(
            camera + " clock offset (ms)",
            clock.offset ? fmt::format("{:+.3f}", clock.offset->offset_ns * 1e-6) : "unknown");
        report.add(camera + " clock round trip (ms)",
                   clock.offset ? fmt::format("{:.3f}", clock.offset->round_trip_ns * 1e-6) : "-");
        report.add(camera + " refused messages", std::to_string(clock.refused));
        if (clock.verdict == ClockVerdict::refused ||
            (clock.verdict == ClockVerdict::unknown && clock.unknown_alerted)) {
          report.flag(HealthLevel::error, clock_problem(c));
        } else if (clock.verdict == ClockVerdict::warned) {
          report.flag(HealthLevel::warn, clock_problem(c));
        }
      }
      if (tracker_.camera_health()[c].drifted) {
        report.flag(HealthLevel::error, fmt::format("camera {} has moved since calibration: "
                                                    "calibrate it again",
                                                    camera));
      } else if (heard_[c] && silent_[c]) {
        report.flag(HealthLevel::warn,
                    fmt::format("camera {} is silent: is its process running?", camera));
      }
    }
  }

 private:
  enum class ClockVerdict { unknown, accepted, warned, refused };
  struct ClockState {
    ClockVerdict verdict = ClockVerdict::unknown;
    std::optional<health::ClockOffset> offset;
    std::string publisher;  // "<process> on <host>"
    std::optional<std::chrono::steady_clock::time_point> first_message;
    bool unknown_alerted = false;
    bool measured_logged = false;  // said once settled
    uint64_t refused = 0;
  };

  // clock_probe_hz a second, and every kSettlingProbePeriod while a camera's clock is not
  // settled: its host answers, or its messages come and are held, then refused, until it does.
  void probe_clocks() {
    const auto steady_now = std::chrono::steady_clock::now();
    bool settling = false;
    for (size_t c = 0; c < tracker_.cameras().size() && !settling; ++c) {
      const health::PeerClocks::Peer* peer = host_clock(c);
      settling = peer != nullptr ? peer->filter.offset() && !settled(*peer->filter.offset())
                                 : clock_states_[c].first_message.has_value();
    }
    if (!settling && steady_now - last_probe_ < seconds(1.0 / settings_.clock_probe_hz)) return;
    send_probe(steady_now);
    clocks_.forget_silent(steady_now, kClockSilence);
  }

  void send_probe(std::chrono::steady_clock::time_point steady_now) {
    last_probe_ = steady_now;
    ClockProbe probe;
    probe.requester(name());
    probe.number(++probe_number_);
    probe.sent(to_time_msg(now()));
    probes_.publish(std::move(probe));
  }

  // The clock of the process that publishes camera `c`'s fiducials; none answered: nullptr.
  const health::PeerClocks::Peer* host_clock(size_t c) const {
    return clocks_.publisher_of(
        topics::member_of(topics::kVolumeFiducials, tracker_.cameras()[c].name));
  }

  void take_clock_reply(const ClockProbeReply& reply) {
    const int64_t received_ns = to_nanoseconds(to_time_msg(now()));
    if (reply.requester() != name()) return;
    clocks_.add(reply.instance(), reply.host(), reply.process(), reply.topics(),
                {to_nanoseconds(reply.probe_sent()), to_nanoseconds(reply.received()),
                 to_nanoseconds(reply.sent()), received_ns},
                std::chrono::steady_clock::now());
    release_held(std::chrono::steady_clock::now());
  }

  void take_fiducials(size_t c, const FiducialArray& array,
                      std::chrono::steady_clock::time_point arrival) {
    frames_.add(static_cast<int>(c), to_nanoseconds(array.header().stamp()), array, arrival);
    arrival_latency_.add(now() - from_time_msg(array.header().stamp()));
    fuse_ready();
  }

  // A message of a camera whose clock is not yet known waits for it as long as its frame would
  // wait for a camera (wait_s): its host is probed at once, and an answer within a millisecond
  // or two settles it, so that a camera's first messages (and a restarted one's) are fused
  // rather than refused for the moment discovery takes. False when it cannot wait.
  bool hold(size_t c, const FiducialArray& array, std::chrono::steady_clock::time_point arrival) {
    if (held_.size() >= kMaxHeld) return false;
    held_.push_back({c, array, arrival});
    if (arrival - last_probe_ >= kHeldProbePeriod) send_probe(arrival);
    return true;
  }

  // Held messages whose camera's clock is now known go on (in their order) or are refused;
  // those that waited wait_s are refused.
  void release_held(std::chrono::steady_clock::time_point now_steady) {
    const auto wait = seconds(settings_.wait_s);
    std::vector<HeldMessage> waiting;
    for (HeldMessage& held : std::exchange(held_, {})) {
      const ClockVerdict verdict = judge_clock(held.camera, now_steady);
      if (verdict == ClockVerdict::accepted || verdict == ClockVerdict::warned) {
        take_fiducials(held.camera, held.array, held.arrival);
      } else if (verdict == ClockVerdict::unknown && now_steady - held.arrival < wait) {
        waiting.push_back(std::move(held));
      } else {
        ++clock_states_[held.camera].refused;
      }
    }
    held_ = std::move(waiting);
  }

  // Camera `c`'s host's clock as the exchanges now prove it (always accepted without
  // check_clocks); a change of verdict is said once.
  ClockVerdict judge_clock(size_t c, std::chrono::steady_clock::time_point arrival) {
    if (!settings_.check_clocks) return ClockVerdict::accepted;
    ClockState& clock = clock_states_[c];
    if (!clock.first_message) clock.first_message = arrival;
    const health::PeerClocks::Peer* peer = host_clock(c);
    clock.offset = peer ? peer->filter.offset() : std::nullopt;
    // Judged on what the exchanges prove: refused once the clock is surely more than the limit
    // off, fused once it is surely within it (a camera is not refused for the network's
    // queues); in between, until an exchange quick enough to tell comes, or enough have.
    ClockVerdict verdict = ClockVerdict::unknown;
    if (clock.offset) {
      clock.publisher = fmt::format("{} on {}", peer->process, peer->host);
      const double least_ms = static_cast<double>(clock.offset->least_offset_ns()) * 1e-6;
      const double most_ms =
          static_cast<double>(std::abs(clock.offset->offset_ns) + clock.offset->round_trip_ns / 2) *
          1e-6;
      if (least_ms > settings_.clock_limit_ms) {
        verdict = ClockVerdict::refused;
      } else if (most_ms <= settings_.clock_limit_ms || settled(*clock.offset)) {
        verdict =
            least_ms > settings_.clock_warning_ms ? ClockVerdict::warned : ClockVerdict::accepted;
      }
      if (!clock.measured_logged && settled(*clock.offset)) {
        clock.measured_logged = true;
        log().info(
            "camera {}: the clock of {} is {:+.3f} ms against this host's (round trip {:.3f} ms), "
            "known {:.2f} s after its first message",
            tracker_.cameras()[c].name, clock.publisher, clock.offset->offset_ns * 1e-6,
            clock.offset->round_trip_ns * 1e-6,
            std::chrono::duration<double>(arrival - *clock.first_message).count());
      }
    }
    if (verdict != clock.verdict) {
      const ClockVerdict was = clock.verdict;
      clock.verdict = verdict;
      if (verdict == ClockVerdict::refused) {
        alert(2, clock_problem(c));
      } else if (verdict == ClockVerdict::warned) {
        alert(1, clock_problem(c));
      } else if (verdict == ClockVerdict::accepted &&
                 (was != ClockVerdict::unknown || clock.unknown_alerted)) {
        alert(1, fmt::format("camera {}: its clock agrees with this host's again ({:+.3f} ms): "
                             "fused",
                             tracker_.cameras()[c].name, clock.offset->offset_ns * 1e-6));
      }
    }
    if (verdict == ClockVerdict::unknown && !clock.unknown_alerted &&
        arrival - *clock.first_message > kUnknownClockAlert) {
      clock.unknown_alerted = true;
      alert(2, clock_problem(c));
    }
    return verdict;
  }

  std::string clock_problem(size_t c) const {
    const std::string& camera = tracker_.cameras()[c].name;
    const ClockState& clock = clock_states_[c];
    if (clock.verdict == ClockVerdict::unknown) {
      return fmt::format(
          "camera {} refused: its clock is unknown (no process that publishes {} answers clock "
          "probes: is its group run by mocap_launch, with its diagnostics?)",
          camera, topics::member_of(topics::kVolumeFiducials, camera));
    }
    const double off_ms = static_cast<double>(clock.offset->offset_ns) * 1e-6;
    return fmt::format(
        "camera {}{}: the clock of {} is {:.3f} ms {} this host's, give or take {:.3f} ms "
        "(warning above {} ms, refused above {} ms): synchronise the hosts' clocks (README: "
        "Clocks)",
        camera, clock.verdict == ClockVerdict::refused ? " refused" : "", clock.publisher,
        std::abs(off_ms), off_ms > 0 ? "ahead of" : "behind",
        static_cast<double>(clock.offset->round_trip_ns) * 0.5e-6, settings_.clock_warning_ms,
        settings_.clock_limit_ms);
  }

  // Latched, for tf2 and viewers: where the cameras are.
  void publish_camera_frames() {
    TFMessage frames;
    std_msgs::msg::Header header;
    header.stamp(to_time_msg(now()));
    header.frame_id("world");
    for (const VolumeCamera& camera : tracker_.cameras()) {
      frames.transforms().push_back(
          to_transform(header, camera.frame_id, camera.camera_from_world.inverse()));
    }
    camera_frames_ = create_publisher<TFMessage>(topics::kTfStatic);
    camera_frames_.publish(frames);
  }

  // A machine too busy to fuse every frame fuses the newest and, of the backlog, no more than
  // keeps the fused frames `behind_max_gap_s` apart (frames_to_fuse): poses late by a backlog
  // are worth less than the next ones, and a backlog only grows, but tracks, identical robots'
  // among them, must not lose their robots across the gap.
  void fuse_ready() {
    std::vector<AssembledFrame<FiducialArray>> ready =
        frames_.take_ready(std::chrono::steady_clock::now());
    if (ready.empty()) return;
    std::vector<int64_t> stamps;
    for (const auto& frame : ready) stamps.push_back(frame.stamp_ns);
    const int64_t max_gap_ns =
        std::max<int64_t>(std::llround(settings_.behind_max_gap_s * 1e9),
                          2 * static_cast<int64_t>(frames_.frame_period().count()));
    const std::vector<size_t> fused =
        frames_to_fuse(stamps, last_fused_ns_, kMaxBacklog, max_gap_ns);
    skipped_frames_ += ready.size() - fused.size();
    for (size_t f : fused) fuse(ready[f]);
    last_fused_ns_ = ready.back().stamp_ns;
  }

  void fuse(const AssembledFrame<FiducialArray>& assembled) {
    const Clock::time_point assembled_at = now();
    report_coverage(assembled);
    std::vector<CameraFrame> frame(assembled.messages.size());
    for (size_t c = 0; c < frame.size(); ++c) {
      const std::optional<FiducialArray>& message = assembled.messages[c];
      if (!message) continue;
      frame[c].received = true;
      frame[c].stamp_ns = to_nanoseconds(message->header().stamp());
      for (const auto& fiducial : message->fiducials()) {
        frame[c].pixels.emplace_back(fiducial.x(), fiducial.y());
        frame[c].pixel_sigma_px.push_back(fiducial.uncertainty());
      }
    }
    const std::vector<TrackedBodyPose> poses = tracker_.track(assembled.stamp_ns, frame);
    ++fused_frames_;
    if (!assembled.complete) ++incomplete_frames_;

    auto message = std::make_shared<ConstellationPoseArray>();
    message->header().stamp(
        to_time_msg(Clock::time_point(std::chrono::nanoseconds(assembled.stamp_ns))));
    message->header().frame_id("world");
    message->data_received(to_time_msg(assembled_at));
    uint32_t late = 0;
    for (size_t c = 0; c < assembled.messages.size(); ++c) {
      late += !assembled.silent[c] && !assembled.messages[c];
    }
    message->cameras_late(late);
    for (const TrackedBodyPose& body : poses) {
      mocap_msgs::msg::ConstellationPose pose =
          pose_message(message->header(), body.name, body.world_from_body, body.covariance);
      pose.reprojection_rms_px(static_cast<float>(body.reprojection_rms_px));
      pose.points_used(static_cast<uint32_t>(body.points_used));
      pose.cameras_used(static_cast<uint32_t>(body.cameras_used));
      if (body.velocity_known) {
        set_velocity(pose, body.linear_velocity, body.angular_velocity, body.velocity_covariance);
      }
      message->poses().push_back(std::move(pose));
      report_single_camera(body, assembled.stamp_ns);
    }
    const std::vector<LabeledMarker> markers =
        track_markers(assembled.stamp_ns, frame, poses, *message);
    const std_msgs::msg::Header header = message->header();
    body_poses_ += poses.size();
    poses_.publish(std::move(message));
    poses_latency_.add(now() - Clock::time_point(std::chrono::nanoseconds(assembled.stamp_ns)));
    fused_rate_.add();
    markers_.publish(std::make_shared<PointCloud2>(to_point_cloud(header, markers)));
    report_unposed(poses, assembled.stamp_ns);
    report_drift();
  }

  // The marker cloud of every camera's detections; the bodies' markers in it labeled, the
  // robots tracked in the rest and added to `message`; the cloud, published after the poses
  // (which its message would otherwise delay).
  std::vector<LabeledMarker> track_markers(int64_t stamp_ns, const std::vector<CameraFrame>& frame,
                                           const std::vector<TrackedBodyPose>& poses,
                                           ConstellationPoseArray& message) {
    std::vector<CameraDetections> detections;
    for (size_t c = 0; c < frame.size(); ++c) {
      const VolumeCamera& camera = tracker_.cameras()[c];
      CameraDetections seen{camera.model.get(), camera.camera_from_world, {}, {}};
      if (frame[c].received && !tracker_.camera_health()[c].drifted) {
        seen.pixels = frame[c].pixels;
        seen.pixel_sigma_px = frame[c].pixel_sigma_px;
      }
      detections.push_back(std::move(seen));
    }
    const std::vector<CloudMarker> cloud = cloud_.track(stamp_ns, detections);
    const std::vector<RigidBody>& bodies = tracker_.bodies().bodies;
    std::vector<PlacedBody> placed;
    std::vector<int> body_index;  // of each placed body in the database
    for (const TrackedBodyPose& pose : poses) {
      const auto body = std::find_if(bodies.begin(), bodies.end(),
                                     [&](const RigidBody& b) { return b.name == pose.name; });
      placed.push_back({pose.world_from_body, &body->markers});
      body_index.push_back(static_cast<int>(body - bodies.begin()));
    }
    std::vector<MarkerOwner> owners = owners_of(cloud, placed, kOwnMarkerRadius_m);
    for (MarkerOwner& owner : owners) {
      if (owner.body >= 0) owner.body = body_index[static_cast<size_t>(owner.body)];
    }
    if (swarm_) {
      std::vector<char> claimed(cloud.size());
      for (size_t m = 0; m < cloud.size(); ++m) claimed[m] = owners[m].body >= 0;
      for (const SwarmRobotPose& robot : swarm_->track(stamp_ns, cloud, claimed)) {
        uint32_t cameras = 0;
        double rms_px = 0;
        uint32_t points = 0;
        for (size_t k = 0; k < robot.markers.size(); ++k) {
          const int m = robot.markers[k];
          if (m < 0) continue;
          owners[static_cast<size_t>(m)] = {static_cast<int>(bodies.size() + robot.robot),
                                            static_cast<int>(k)};
          cameras |= cloud[static_cast<size_t>(m)].cameras;
          rms_px += cloud[static_cast<size_t>(m)].rms_px;
          points += static_cast<uint32_t>(cloud[static_cast<size_t>(m)].observations.size());
        }
        mocap_msgs::msg::ConstellationPose pose =
            pose_message(message.header(), swarm_->swarm().robots[robot.robot].name,
                         robot.world_from_body, robot.covariance);
        pose.reprojection_rms_px(static_cast<float>(rms_px / robot.markers_used));
        pose.points_used(points);
        pose.cameras_used(static_cast<uint32_t>(std::popcount(cameras)));
        if (robot.velocity_known) {
          set_velocity(pose, robot.linear_velocity, robot.angular_velocity,
                       robot.velocity_covariance);
        }
        message.poses().push_back(std::move(pose));
        ++robot_poses_;
      }
    }
    std::vector<LabeledMarker> labeled;
    for (size_t m = 0; m < cloud.size(); ++m) {
      labeled.push_back({cloud[m].position.cast<float>(), owners[m].body,
                         static_cast<uint16_t>(owners[m].marker), cloud[m].id,
                         static_cast<float>(cloud[m].rms_px), cloud[m].cameras});
    }
    return labeled;
  }

  void reseed(const NamedPoseArray& array) {
    for (const auto& named : array.poses()) {
      const auto& p = named.pose().position();
      const Eigen::Vector3d position(p.x(), p.y(), p.z());
      if (swarm_ && swarm_->reseed(named.name(), position)) {
        log().info("{}: looked for at ({:.3f}, {:.3f}, {:.3f})", named.name(), p.x(), p.y(), p.z());
      } else {
        log().warn("re-seed: no robot '{}' in the swarm{}", named.name(),
                   swarm_ ? "" : " (no robots file)");
      }
    }
  }

  // A body posed before and not for kUnposedAlert is said to be seen too poorly to pose: too
  // few of its markers in view, or views that disagree; a wrong pose is not handed out instead.
  void report_unposed(const std::vector<TrackedBodyPose>& poses, int64_t stamp_ns) {
    for (const RigidBody& body : tracker_.bodies().bodies) {
      Unposed& state = unposed_[body.name];
      const bool posed = std::any_of(poses.begin(), poses.end(),
                                     [&](const TrackedBodyPose& p) { return p.name == body.name; });
      if (posed) {
        if (state.reported) log().info("{} is posed again", body.name);
        state = {stamp_ns, false};
        continue;
      }
      if (state.last_posed_ns == 0 || state.reported ||
          stamp_ns - state.last_posed_ns < std::chrono::nanoseconds(kUnposedAlert).count()) {
        continue;
      }
      state.reported = true;
      alert(1,
            fmt::format("{} has not been posed for {} s: seen too poorly to pose (too few of its "
                        "markers, or cameras that disagree)",
                        body.name, std::chrono::duration<double>(kUnposedAlert).count()));
    }
  }

  // A camera not heard yet is left out as a silent one, but is not news until it was heard.
  void report_coverage(const AssembledFrame<FiducialArray>& frame) {
    for (size_t c = 0; c < silent_.size(); ++c) {
      const std::string& name = tracker_.cameras()[c].name;
      if (!frame.silent[c] && !heard_[c]) {
        heard_[c] = true;
        log().info("camera {}: first fiducials", name);
      }
      // A camera back after a gap too short to call it silent (a restarted process, a busy
      // host): said, so that a user sees the frames fused without it.
      Gap& gap = gaps_[c];
      if (!frame.messages[c]) {
        if (heard_[c] && gap.frames++ == 0) gap.since_ns = frame.stamp_ns;
      } else if (gap.frames > 0) {
        if (gap.frames >= kGapFramesLogged) {
          log().info("camera {}: fiducials again after {:.2f} s ({} frame(s) fused without it)",
                     name, static_cast<double>(frame.stamp_ns - gap.since_ns) * 1e-9, gap.frames);
        }
        gap = {};
      }
      if (frame.silent[c] == silent_[c] || !heard_[c]) continue;
      silent_[c] = frame.silent[c];
      if (silent_[c]) {
        alert(1, fmt::format("camera {} is silent: no fiducials for {} s; fusing without it", name,
                             settings_.silent_after_s));
      } else {
        alert(1, fmt::format("camera {} is back", name));
      }
    }
  }

  // Said once a body has rested on one camera for kSingleCameraAlert: a body passing out of
  // the others' views for a frame or two is no news.
  void report_single_camera(const TrackedBodyPose& body, int64_t stamp_ns) {
    std::optional<SingleCamera>& single = single_camera_[body.name];
    if (body.cameras_used != 1) {
      single.reset();
      return;
    }
    ++single_camera_poses_;
    if (!single) single = SingleCamera{stamp_ns, false};
    if (!single->reported &&
        stamp_ns - single->since_ns >= std::chrono::nanoseconds(kSingleCameraAlert).count()) {
      single->reported = true;
      alert(1, fmt::format("{} is seen by one camera only for {} s: its depth is poor", body.name,
                           std::chrono::duration<double>(kSingleCameraAlert).count()));
    }
  }

  void report_drift() {
    for (size_t c = 0; c < drifted_.size(); ++c) {
      const CameraHealth& health = tracker_.camera_health()[c];
      if (!health.drifted || drifted_[c]) continue;
      drifted_[c] = true;
      alert(2, fmt::format("camera {} has moved since calibration: residual {:.1f} px against "
                           "the other cameras' poses; left out, calibrate it again",
                           tracker_.cameras()[c].name, health.average_error_px));
    }
  }

  void alert(uint8_t level, const std::string& text) {
    if (level >= 2) {
      log().error("{}", text);
    } else {
      log().warn("{}", text);
    }
    auto message = std::make_shared<Alert>();
    message->header().stamp(to_time_msg(now()));
    message->source(name());
    message->level(level);
    message->text(text);
    alerts_.publish(std::move(message));
  }

  VolumeTracker tracker_;
  MarkerCloudTracker cloud_;
  std::optional<SwarmTracker> swarm_;
  FrameAssembler<FiducialArray> frames_;
  std::vector<bool> heard_;   // per camera
  std::vector<bool> silent_;  // per camera, as last reported
  struct Gap {
    int64_t since_ns = 0;  // the first frame without the camera
    int frames = 0;        // frames without it since
  };
  std::vector<Gap> gaps_;      // per camera
  std::vector<bool> drifted_;  // per camera, as last reported
  struct SingleCamera {
    int64_t since_ns = 0;
    bool reported = false;
  };
  std::map<std::string, std::optional<SingleCamera>> single_camera_;  // by body
  struct Unposed {
    int64_t last_posed_ns = 0;  // 0: never posed
    bool reported = false;
  };
  std::map<std::string, Unposed> unposed_;  // by body
  uint64_t single_camera_poses_ = 0;
  Publisher<ConstellationPoseArray> poses_;
  Publisher<PointCloud2> markers_;
  Publisher<Alert> alerts_;
  Publisher<TFMessage> camera_frames_;
  uint64_t fused_frames_ = 0;
  uint64_t incomplete_frames_ = 0;
  uint64_t skipped_frames_ = 0;  // behind: not among the frames_to_fuse
  std::optional<int64_t> last_fused_ns_;
  uint64_t body_poses_ = 0;
  uint64_t robot_poses_ = 0;
  std::vector<ClockState> clock_states_;  // per camera
  health::PeerClocks clocks_;
  Publisher<ClockProbe> probes_;
  uint32_t probe_number_ = 0;
  std::chrono::steady_clock::time_point last_probe_{};
  struct HeldMessage {
    size_t camera = 0;
    FiducialArray array;
    std::chrono::steady_clock::time_point arrival;
  };
  std::vector<HeldMessage> held_;
  LatencyFigures arrival_latency_;
  LatencyFigures poses_latency_;
  RateFigures fused_rate_;
};

}  // namespace
}  // namespace mocap::volume

MOCAP_REGISTER_COMPONENT(mocap::volume::VolumeFusion, "volume_fusion")
