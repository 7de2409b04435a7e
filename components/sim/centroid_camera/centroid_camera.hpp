// What a motion-capture camera that sends centroids, not images, reports of a scene's markers:
// each marker's image centre with the sensor's sub-pixel error, without rendering a pixel.
// Markers whose images overlap come out as one blob at their area-weighted centre (a real
// camera's centroid of a merged blob), markers whose image the frame's edge cuts and markers
// hidden (behind an opaque sphere: a robot's frame, or an image-space occluder) are not
// reported. This is what lets eight cameras at 240 Hz run on a small machine, where rendering
// 1280x720 images for each would not.
//
//   CentroidCamera camera(model, camera_from_world, options, seed);
//   std::vector<Centroid> seen = camera.project(markers, spheres);
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

#include "sim/centroid_camera/occluding_sphere.hpp"

namespace mocap::synthetic {

struct CentroidCameraOptions {
  double marker_diameter_m = 0.014;  // spherical markers, as on a Crazyflie's marker deck
  // The 1-sigma error of a centroid along each image axis (pixels). The volume demo's rendered
  // 1280x720 images give about 0.03 px.
  double noise_px = 0.05;
  // A marker's image is never narrower than this (pixels): optics and the sensor's pixels
  // spread even a far marker over a few.
  double min_diameter_px = 2.0;

  // Why these options cannot be used, naming the field ("noise_px: -1 is below 0"); nullopt
  // when they can. CentroidCamera's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct Centroid {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double diameter_px = 0;
  // The error the camera states for it: the noise, and for a merged blob how far its markers'
  // centres lie from the blob's (a merged centroid is not any one marker's).
  double sigma_px = 0;
  std::vector<int> markers;  // the indices of the markers it shows, in ascending order
};

class CentroidCamera {
 public:
  // Throws std::invalid_argument for bad options.
  CentroidCamera(std::shared_ptr<const calibration::CameraModel> model,
                 const Eigen::Isometry3d& camera_from_world, CentroidCameraOptions options,
                 uint64_t seed);

  // One frame's centroids of `markers` (world frame, metres), in no particular order; each
  // call draws new noise. `hidden_regions` are image rectangles an occluder covers.
  std::vector<Centroid> project(const std::vector<Eigen::Vector3d>& markers,
                                const std::vector<OccludingSphere>& spheres = {},
                                const std::vector<Eigen::AlignedBox2d>& hidden_regions = {});

  const calibration::CameraModel& model() const { return *model_; }
  const Eigen::Isometry3d& camera_from_world() const { return camera_from_world_; }

 private:
  std::shared_ptr<const calibration::CameraModel> model_;
  Eigen::Isometry3d camera_from_world_;
  Eigen::Vector3d centre_in_world_;
  CentroidCameraOptions options_;
  std::mt19937_64 random_;
};

}  // namespace mocap::synthetic
