// The graph's default topic names, one place for every component, each with the type it
// carries. They are part of the interface (README "Messages"); a launch file may remap any of
// them. A name with {board} or {camera} in it is a family: one topic per board or camera.
#pragma once

#include <string>
#include <string_view>

namespace mocap::topics {

// Cameras.
inline constexpr const char* kCameraImage = "/camera/ir/image_raw";     // sensor_msgs/Image
inline constexpr const char* kCameraInfo = "/camera/ir/camera_info";    // sensor_msgs/CameraInfo
inline constexpr const char* kGroundTruth = "/camera/ir/ground_truth";  // ConstellationPoseArray
inline constexpr const char* kSimCameraPose = "/sim/camera_pose";       // PoseStamped, world

// Tracking.
inline constexpr const char* kFiducials = "/mocap/fiducials";            // mocap_msgs/FiducialArray
inline constexpr const char* kConstellations = "/mocap/constellations";  // ConstellationArray
inline constexpr const char* kPoses = "/mocap/poses";      // mocap_msgs/ConstellationPoseArray
inline constexpr const char* kOverlay = "/mocap/overlay";  // sensor_msgs/Image, bgr8
inline constexpr const char* kDemoFiducials = "/demo/fiducials";  // FiducialArray, a stand-in

// A volume of fixed cameras.
inline constexpr const char* kVolumeFiducials = "/volume/{camera}/fiducials";  // FiducialArray
inline constexpr const char* kMarkers = "/mocap/markers";  // sensor_msgs/PointCloud2, world
// A robot carried away by hand, to be looked for where it now is: each name at its position.
inline constexpr const char* kReseed =
    "/mocap/reseed";  // motion_capture_tracking_interfaces/NamedPoseArray

// The poses as other tools read them.
inline constexpr const char* kBoardPose = "/mocap/{board}/pose";      // PoseStamped
inline constexpr const char* kBoardOdometry = "/mocap/{board}/odom";  // nav_msgs/Odometry
inline constexpr const char* kTf = "/tf";                             // tf2_msgs/TFMessage
inline constexpr const char* kTfStatic = "/tf_static";                // tf2_msgs/TFMessage
// Every body of a frame by name, as crazyswarm2 reads a swarm's poses.
inline constexpr const char* kNamedPoses =
    "/poses";  // motion_capture_tracking_interfaces/NamedPoseArray
inline constexpr const char* kPx4VisualOdometry =
    "/fmu/in/vehicle_visual_odometry";  // px4_msgs/VehicleOdometry

// The followers and their robots.
inline constexpr const char* kTurretCommand = "/turret/command";           // JointState
inline constexpr const char* kTurretJointStates = "/turret/joint_states";  // JointState
inline constexpr const char* kCmdVel = "/cmd_vel";                         // geometry_msgs/Twist
inline constexpr const char* kBasePose = "/base/pose";                     // PoseStamped, world
inline constexpr const char* kAlerts = "/alerts";                          // mocap_msgs/Alert

// Health: every process's statuses, and the clock probes a fusion measures hosts' clocks with.
inline constexpr const char* kDiagnostics = "/diagnostics";       // diagnostic_msgs/DiagnosticArray
inline constexpr const char* kClockProbe = "/mocap/clock/probe";  // mocap_msgs/ClockProbe
inline constexpr const char* kClockReply = "/mocap/clock/reply";  // mocap_msgs/ClockProbeReply

// Volume calibration.
inline constexpr const char* kVolumeConstellations =
    "/volume/{camera}/constellations";  // mocap_msgs/ConstellationArray
inline constexpr const char* kCalibrationCoverage =
    "/calibration/coverage";  // mocap_msgs/CalibrationCoverage
inline constexpr const char* kCalibrationProgress =
    "/calibration/progress";  // mocap_msgs/CalibrationProgress
inline constexpr const char* kCalibrationResult =
    "/calibration/result";  // mocap_msgs/VolumeCalibrationResult

// PixArt localization.
inline constexpr const char* kPixartRaw = "/pixart/raw";  // mocap_msgs/PixartRawPointArray
inline constexpr const char* kPixartFiducials = "/pixart/{camera}/fiducials";  // FiducialArray
inline constexpr const char* kPixartRobots = "/pixart/robots";  // mocap_msgs/RobotPoseArray
inline constexpr const char* kPixartGroundTruth = "/pixart/ground_truth";  // RobotPoseArray
inline constexpr const char* kPixartFootprints =
    "/pixart/camera_footprints";  // mocap_msgs/CameraFootprintArray

// The topic of `family` for `member`: "/mocap/{board}/pose", "board_a" -> "/mocap/board_a/pose".
inline std::string member_of(std::string_view family, std::string_view member) {
  const size_t open = family.find('{');
  const size_t close = family.find('}', open);
  std::string topic(family.substr(0, open));
  topic += member;
  topic += family.substr(close + 1);
  return topic;
}

}  // namespace mocap::topics
