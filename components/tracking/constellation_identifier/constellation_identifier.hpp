// Names the constellations in a set of image points (seed 000 §5.9): collinear groups, then
// lines by cross-ratio, then boards from lines that fit one plane.
//
//   ConstellationIdentifier identifier(database, options);
//   for (const IdentifiedConstellation& found : identifier.identify(points)) ...
//
// Done better than the seed: every line of every constellation is looked for in both point
// orders; a constellation needs `min_lines` of its lines, at the database's shared points and
// on one plane (a homography from its plane to the image fits every point within
// `max_fit_error_px`), so chance alignments of distractors are rejected before the pose; and
// all constellations in view are reported, each image point used by one at most.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tracking/constellation_database/constellation_database.hpp"
#include "tracking/constellation_identifier/line_search.hpp"

namespace mocap::constellations {

struct IdentifierOptions {
  LineSearchOptions line_search;
  // Largest relative difference between a measured and a database cross-ratio (seed eq. 8).
  // The seed used 0.20 with errors below 0.05; a tighter value tells more line types apart.
  double cross_ratio_tolerance = 0.03;
  // Fewest lines of a constellation that identify it; capped at its number of lines. With the
  // shipped database three lines name a board uniquely.
  int min_lines = 3;
  // A constellation with fewer whole lines than min_lines, but at least two that share a
  // marker, is identified when this many of its other markers lie where its plane puts them
  // (a board with a corner hidden keeps only two whole sides and four other markers). 0
  // disables it. Two let chance alignments through (about one in 1000 frames of 60 random
  // points with distractor lines, test_constellation_identifier).
  int min_extra_markers = 3;
  // Largest distance, pixels, of an identified point from where the plane-to-image
  // homography of all identified points puts it.
  double max_fit_error_px = 3.0;
  // A line's four points are taken from at most this many consecutive points of a group, so
  // a group holding several boards' sides yields a handful of candidates, not C(n, 4).
  int candidate_window = 6;
  // Pixels per unit of the points' coordinates when they are a calibrated camera's ideal
  // pixels, f·(x/z, y/z) (the principal point at the origin, as the tracker and the identifier
  // plugin with a camera pass them); 0 when they are not. With it, a constellation of which a
  // single whole line is seen is found by its loose markers (min_loose_markers below).
  double focal_length_px = 0;
  // Fewest loose markers (off the one whole line) that must land where the line's place in
  // space and one turn about it put them, for a constellation seen by one line only; 0 turns
  // that search off. Needs focal_length_px.
  int min_loose_markers = 3;

  // Why these options cannot be used, naming the field (the line search's by its path:
  // "line_search.tolerance_px: 0 is not above 0"); nullopt when they can.
  // ConstellationIdentifier's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

struct IdentifiedLine {
  int model_line = 0;                 // index into ConstellationModel::lines
  std::array<int, 4> image_points{};  // image point indices in the model's order A..D
  double cross_ratio = 0;             // as measured
};

struct IdentifiedConstellation {
  const ConstellationModel* model = nullptr;
  std::vector<IdentifiedLine> lines;  // whole lines found by cross-ratio, in the model's order
  // Per model point: image point index, or -1 if unseen. Besides the whole lines' points it
  // holds the markers of broken lines found where the plane of the whole lines puts them.
  std::vector<int> image_point_of;
  double fit_rms_px = 0;  // of the plane-to-image homography over all points
  double fit_max_px = 0;
  // Found from one whole line and loose markers (IdentifierOptions::min_loose_markers): a
  // weaker identification, which a caller with the camera should verify by its pose.
  bool from_one_line = false;
  int points_identified() const;
};

struct IdentificationStats {
  size_t groups = 0;               // collinear groups of >= 4 points
  size_t candidates = 0;           // four-point candidates measured
  size_t matched = 0;              // candidates whose cross-ratio matched a line type
  size_t rejected_by_fit = 0;      // constellations found by lines but rejected by the plane fit
  size_t conflicts = 0;            // constellations dropped because a better one took their points
  size_t one_line_hypotheses = 0;  // line placements tried for constellations seen by one line
};

class ConstellationIdentifier {
 public:
  // Keeps a reference to `database`, which must outlive the identifier. Throws
  // std::invalid_argument for options that cannot be used.
  explicit ConstellationIdentifier(const ConstellationDatabase& database,
                                   IdentifierOptions options = {});

  // `points` in pixels, free of lens distortion (lines must be straight for the cross-ratio
  // to hold). Non-finite points are ignored.
  std::vector<IdentifiedConstellation> identify(const std::vector<Eigen::Vector2d>& points,
                                                IdentificationStats* stats = nullptr) const;

  const IdentifierOptions& options() const { return options_; }

 private:
  struct LineType {
    std::string name;
    double cross_ratio;
  };
  const ConstellationDatabase& database_;
  IdentifierOptions options_;
  std::vector<LineType> line_types_;
  // Per constellation, per line: index into line_types_.
  std::vector<std::vector<int>> line_type_of_;
};

}  // namespace mocap::constellations
