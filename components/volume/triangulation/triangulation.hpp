// Markers in 3D from the 2D markers of several fixed, calibrated cameras, without labels: which
// detection in one camera is which in another is found by the geometry alone.
//
// Every pair of cameras proposes a marker for each pair of their detections whose two rays
// meet (triangulated, it reprojects within the tolerance in both); each proposal gathers the
// detections of the other cameras that it reprojects onto, and is triangulated again from all
// of them. Proposals seen by the most cameras, then with the lowest reprojection error, are
// taken first, and a detection belongs to one marker.
//
//   std::vector<CameraDetections> cameras = ...;  // each camera's model, extrinsics, pixels
//   std::vector<TriangulatedMarker> markers = triangulate_markers(cameras);
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

namespace mocap::volume {

struct CameraDetections {
  const calibration::CameraModel* camera = nullptr;
  Eigen::Isometry3d camera_from_world = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector2d> pixels;  // the markers this camera found, in any order
  // Each pixel's 1-sigma error (the detector's uncertainty), index by index; empty: all alike.
  // The fusion weighs each point by it: a faint or merged blob errs several times more than a
  // bright round one.
  std::vector<double> pixel_sigma_px;
};

struct MarkerTriangulationOptions {
  // How far a marker may reproject from a detection that sees it (pixels).
  double tolerance_px = 1.5;
  // Fewest cameras that must see a marker (at least 2).
  int min_cameras = 2;
  // Why these options cannot be used, naming the field ("tolerance_px: 0 is not above 0");
  // nullopt when they can. The functions that take them throw std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct TriangulatedMarker {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame, metres
  // (camera, detection) pairs: the camera's index and the index of its pixel.
  std::vector<std::pair<int, int>> observations;
  double rms_px = 0;  // reprojection error over the observations
};

std::vector<TriangulatedMarker> triangulate_markers(const std::vector<CameraDetections>& cameras,
                                                    const MarkerTriangulationOptions& options = {});

// The point that best fits the observations: the rays' closest point, then refined on the pixel
// reprojection error. nullopt when a pixel has no ray or the point is behind a camera.
std::optional<Eigen::Vector3d> triangulate_point(const std::vector<CameraDetections>& cameras,
                                                 const std::vector<std::pair<int, int>>& seen);

}  // namespace mocap::volume
