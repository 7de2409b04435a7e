// The constellations a tracker can recognise: planar groups of markers made of linear
// sub-constellations of four points (seed 000 §5.9.1–5.9.2), with their geometry in metres.
//
// Three file forms are read:
//  - the seed's sub-constellation CSV: `Name,pt_A,pt_B,pt_C,pt_D`, then one line type per
//    row with the points' distances in millimetres from the first point;
//  - the seed's constellation CSV: blocks of `Const_ID,<id>`, `Pts,<line names…>`,
//    `Name,X_coord,Y_coord,Z_coord`, then per line a row `<name>,cx,cy,cz` (its centroid)
//    followed by four rows `,x,y,z` (metres, in line order);
//  - YAML (config/constellations.yaml documents it): both in one file.
#pragma once

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace mocap::constellations {

// A line type from the sub-constellation table.
struct LinePattern {
  std::string name;
  std::array<double, 4> positions_m{};  // along the line from the first point, increasing
  double cross_ratio = 0;
};

// One line of a constellation.
struct ConstellationLine {
  std::string name;
  std::array<int, 4> points{};  // indices into ConstellationModel::points, A to D
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  // What an image of this line must measure: the line pattern's value when the
  // sub-constellation table names it (as the seed did), else from the line's own geometry.
  double cross_ratio = 0;
};

struct ConstellationModel {
  std::string name;
  // Every distinct marker once (a corner shared by two lines is one point), metres, in the
  // constellation's frame.
  std::vector<Eigen::Vector3d> points;
  std::vector<ConstellationLine> lines;
  // The plane of the markers: points[i] = plane_origin + plane_axes * plane_points[i].
  Eigen::Vector3d plane_origin = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 2> plane_axes = Eigen::Matrix<double, 3, 2>::Zero();
  std::vector<Eigen::Vector2d> plane_points;
  double size_m = 0;  // largest distance between two markers

  // Names of the lines, in file order (the seed's `Pts` row).
  std::vector<std::string> line_names() const;
};

// Why a database file cannot be used; starts with "FILE:LINE:" where a line is known.
class DatabaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ConstellationDatabase {
 public:
  ConstellationDatabase() = default;
  // Checks and completes the models (shared points, planes, cross-ratios); throws
  // DatabaseError naming `source` when a constellation is unusable.
  ConstellationDatabase(std::vector<LinePattern> patterns,
                        std::vector<ConstellationModel> constellations, const std::string& source);

  const std::vector<LinePattern>& line_patterns() const { return patterns_; }
  const std::vector<ConstellationModel>& constellations() const { return constellations_; }
  const ConstellationModel* find(std::string_view name) const;
  const LinePattern* find_pattern(std::string_view name) const;

  // Line types whose cross-ratios are so close that a measurement within `tolerance`
  // (relative) of one could be the other: one sentence per pair, empty when all are apart.
  std::vector<std::string> ambiguities(double tolerance) const;

 private:
  std::vector<LinePattern> patterns_;
  std::vector<ConstellationModel> constellations_;
};

// `constellations_file` is YAML (.yaml, .yml) or the seed's constellation CSV; the optional
// `sub_constellations_csv` is the seed's sub-constellation table.
ConstellationDatabase load_database(const std::string& constellations_file,
                                    const std::string& sub_constellations_csv = "");

// The parsers behind load_database; `source` names the text in errors.
std::vector<LinePattern> parse_sub_constellation_csv(std::string_view text,
                                                     const std::string& source);
std::vector<ConstellationModel> parse_constellation_csv(std::string_view text,
                                                        const std::string& source);
// `more_patterns` (a sub-constellation table's) join the file's own line patterns before the
// constellations are checked and completed.
ConstellationDatabase parse_database_yaml(const std::string& text, const std::string& source,
                                          std::vector<LinePattern> more_patterns = {});

}  // namespace mocap::constellations
