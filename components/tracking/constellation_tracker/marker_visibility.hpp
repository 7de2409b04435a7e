// Which of a body's markers the camera should see at a pose, and whether the ones it does not
// see can be hidden: what the tracker checks before it believes a pose (the reprojection check
// of the pose estimator, made to hold the markers that are missing as well as the ones found).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <mocap/calibration/camera_model.hpp>

#include "tracking/constellation_database/constellation_database.hpp"

namespace mocap::tracking {

enum class MarkerSight {
  InView,        // in front, facing the camera, inside the image
  OutOfFrame,    // its image falls outside the picture (or on its border)
  FacingAway,    // its board turns it away from the camera, or nearly edge-on
  BehindCamera,  // the camera cannot image it at all
};

struct MarkerImage {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // where it is imaged (when it can be)
  MarkerSight sight = MarkerSight::BehindCamera;
};

struct VisibilityOptions {
  // Markers are flat discs facing the body's +z (the database's convention, as the synthetic
  // camera draws them). Turned further than this from the camera, a disc is too thin an
  // ellipse for the fiducial detector's roundness test.
  double max_view_angle_deg = 70;
  // A marker imaged this close to the image border may be cut by it: not expected.
  double border_margin_px = 3;

  // Why these options cannot be used, naming the field ("max_view_angle_deg: 100 is not in
  // [0, 90]"); nullopt when they can. marker_images throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

std::vector<MarkerImage> marker_images(const calibration::CameraModel& camera,
                                       const constellations::ConstellationModel& model,
                                       const Eigen::Isometry3d& camera_from_body,
                                       const VisibilityOptions& options = {});

// True when one straight band of the image (the strip between two parallel lines, or a
// half-plane) can cover every point of `hidden` but at most `spare` of them, and none of
// `seen`: what one occluder in front of a board hides, a hand over a corner, a pole across the
// middle, an arm from one side (and `spare` markers lost to a glare or a fingertip elsewhere).
// Markers missing in plain view, with seen ones between them, are not covered; a lone one
// always is (a thin band passes between its neighbours).
bool one_band_covers(const std::vector<Eigen::Vector2d>& hidden,
                     const std::vector<Eigen::Vector2d>& seen, int spare = 0);

// True when the line of sight to `point` (camera frame) crosses the board of `model` at
// `camera_from_board` before reaching it: the board's plane, within the rectangle of its
// markers grown by `margin_m` (the board reaches a little beyond its outer markers).
bool behind_board(const Eigen::Vector3d& point, const constellations::ConstellationModel& model,
                  const Eigen::Isometry3d& camera_from_board, double margin_m = 0.02);

}  // namespace mocap::tracking
