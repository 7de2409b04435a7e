// Finds a constellation of which one whole line is seen, completed by its loose markers: a
// board with a corner or a side hidden, or half out of the picture, keeps one side whole and
// a few markers of the others.
//
// In a calibrated camera four collinear markers at known distances fix their line in space: a
// line seen at one size and with one foreshortening can only lie in one place. That leaves the
// board one freedom, a turn about the line. Each loose marker of the board seen at an image
// point names the turn that would put it there; a turn that two or more loose markers agree on
// places the whole board, which is then completed with every marker that lands on an image
// point and checked by its plane fit. Hypotheses are few (the line's candidates times the
// lines of that type) and each costs one pass over the nearby points.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "tracking/constellation_identifier/constellation_identifier.hpp"
#include "tracking/constellation_identifier/line_candidate.hpp"

namespace mocap::constellations {

struct LineInSpace {
  Eigen::Vector3d start = Eigen::Vector3d::Zero();       // the first marker, camera frame, metres
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // unit, from the first marker on
  double rms_error = 0;  // of the markers' reprojections, normalised image units
};

// The line whose markers lie `along_m` metres from its first one (increasing from 0) and are
// seen at `normalised` image points (x/z, y/z); nothing when no line in front of the camera
// fits them.
std::optional<LineInSpace> place_line(const std::array<Eigen::Vector2d, 4>& normalised,
                                      const std::array<double, 4>& along_m);

// The best identification of `model` from one of its whole lines and at least
// options.min_loose_markers of its other markers, using only points not `taken`. `points` are
// ideal pixels, f·(x/z, y/z) with f = options.focal_length_px; `by_type` holds the line
// candidates per line type and `type_of_line` each model line's type.
std::optional<IdentifiedConstellation> find_from_one_line(
    const ConstellationModel& model, const std::vector<int>& type_of_line,
    const std::vector<std::vector<Candidate>>& by_type, const std::vector<Eigen::Vector2d>& points,
    const std::vector<bool>& taken, const IdentifierOptions& options, IdentificationStats& stats);

}  // namespace mocap::constellations
