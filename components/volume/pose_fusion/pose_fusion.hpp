// The pose of a rigid body seen by several fixed, calibrated cameras: the world pose that
// minimises the pixel reprojection error over every camera that sees it, with its covariance.
// One camera's view fixes depth poorly (a board's distance rests on its apparent size); views
// from several sides fix it as well as the rest, which is what a volume of cameras is for.
//
//   std::vector<CameraView> views = ...;  // each camera's extrinsics and identified points
//   MultiCameraPose fused = estimate_multi_camera_pose(views, start);
//   if (fused.valid) publish(fused.world_from_body, fused.covariance);
//
// The start is any pose near the answer: a single camera's pose of the body (planar_pose.hpp)
// moved into the world frame, or the track's prediction.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

#include "volume/triangulation/triangulation.hpp"

namespace mocap::volume {

// What one camera saw of the body: its points in the body's frame and the pixels they were
// seen at, index by index.
struct CameraView {
  const calibration::CameraModel* camera = nullptr;
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();  // the extrinsics
  std::vector<Eigen::Vector3d> body_points;                             // metres, body frame
  std::vector<Eigen::Vector2d> pixels;
  // Each pixel's 1-sigma error, index by index; empty: all alike. Each point's residual counts
  // divided by it; the RMS figures stay in pixels.
  std::vector<double> pixel_sigma_px;
};

struct MultiCameraPoseOptions {
  // A pose whose RMS reprojection error over all views exceeds this is rejected: a camera
  // that identified something else, or whose extrinsics have moved.
  double max_reprojection_rms_px = 1.5;
  // Fewest points over all views; at least three (fewer throw std::invalid_argument).
  int min_points = 4;
  // A pose its points do not fix is rejected: one whose covariance gives its orientation a
  // standard deviation about its worst axis more than this many times that about its best.
  // Points on one line of the body, as when two cameras each see a few markers of one side,
  // leave it free to turn about that line, and the least-squares pose lands anywhere along that
  // freedom as well fitted as the right one (on the demo's images: 34 mm and 11 degrees off at
  // 0.9 sigmas RMS, the ratio 2,800). A ratio, not sigmas in degrees, so that it holds whatever
  // the cameras' resolution and the pixels' sigmas: sound fits, one camera's included, lie at 1.5
  // to 6 over the tests' 170,000 fits of rendered and synthetic volumes.
  double max_orientation_sigma_ratio = 30;
  int max_iterations = 20;
  // Why these options cannot be used, naming the field ("tolerance_px: 0 is not above 0");
  // nullopt when they can. The functions that take them throw std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct MultiCameraPose {
  bool valid = false;
  std::string rejection;  // why not valid
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  double reprojection_rms_px = 0;  // over every point of every view used
  // The residuals' RMS in units of each pixel's sigma (pixel_sigma_px; 1 px where none is
  // given): about 1 when the points are the body's markers and the sigmas say how the
  // detector errs, far above when a point is something else.
  double normalized_rms = 0;
  int cameras_used = 0;  // views with at least one point; 1: a single camera's pose
  int points_used = 0;
  // Row-major 6x6 over (x, y, z, rx, ry, rz) of the body's origin in the world frame (m, rad;
  // rotation as a small angle vector in the world frame), from the residual scatter.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Each view's RMS reprojection error at the fused pose, in the order of the views (0 for a
  // view without points): a camera far above the others has moved or misidentified.
  std::vector<double> view_rms_px;
};

// Each camera's view of a body at about `world_from_body`: each of `body_points` paired with
// the camera's detection within `radius_px` of where the pose projects it, when each is the
// other's nearest. Markers that only one camera sees count here, where triangulation needs two.
std::vector<CameraView> views_near(const std::vector<CameraDetections>& cameras,
                                   const std::vector<Eigen::Vector3d>& body_points,
                                   const Eigen::Isometry3d& world_from_body, double radius_px);

MultiCameraPose estimate_multi_camera_pose(const std::vector<CameraView>& views,
                                           const Eigen::Isometry3d& start,
                                           const MultiCameraPoseOptions& options = {});

// For each view, the RMS reprojection error of the other views fused without it: a camera that
// moved after calibration is the one whose removal leaves the others agreeing to the noise,
// where the fused pose of all of them spreads its error over every view. NaN where the others
// fix no pose.
std::vector<double> rms_without_each_view_px(const std::vector<CameraView>& views,
                                             const Eigen::Isometry3d& start,
                                             const MultiCameraPoseOptions& options = {});

}  // namespace mocap::volume
