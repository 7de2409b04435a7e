#include "tracking/constellation_identifier/one_line_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "tracking/constellation_database/plane_homography.hpp"

namespace mocap::constellations {
namespace {

// One loose marker seen at one image point: the turn about the line that puts it there.
struct Vote {
  double angle = 0;
  int marker = 0;
  int point = 0;
};

// Two loose markers name the same turn when their votes are this close, radians: the line's
// tilt error moves votes apart, a wrong pairing by much more.
constexpr double kMaxTurnDisagreement = 0.3;

double angle_difference(double a, double b) {
  double d = std::fmod(a - b, 2 * M_PI);
  if (d > M_PI) d -= 2 * M_PI;
  if (d < -M_PI) d += 2 * M_PI;
  return d;
}

// A line's own axes in the model: its first marker, along it, across it in the board's
// plane, and the plane's normal.
struct LineAxes {
  Eigen::Vector3d origin, along, across, normal;
};

// A board hinged on a placed line: where its markers are for each turn about the line.
class BoardOnLine {
 public:
  BoardOnLine(const ConstellationModel& model, const ConstellationLine& line,
              const LineInSpace& placed)
      : model_(model), placed_(placed) {
    model_axes_.origin = model.points[line.points[0]];
    model_axes_.along = (model.points[line.points[3]] - model_axes_.origin).normalized();
    model_axes_.normal = model.plane_axes.col(0).cross(model.plane_axes.col(1)).normalized();
    model_axes_.across = model_axes_.normal.cross(model_axes_.along);
    // Any two unit vectors across the placed line: the turn angle is measured from e1_.
    Eigen::Vector3d helper =
        std::abs(placed.direction.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    e1_ = placed.direction.cross(helper).normalized();
    e2_ = placed.direction.cross(e1_);
  }

  // Marker m's offsets along and across the line.
  Eigen::Vector2d offsets(int marker) const {
    Eigen::Vector3d q = model_.points[marker] - model_axes_.origin;
    return {q.dot(model_axes_.along), q.dot(model_axes_.across)};
  }

  // Where a marker with these offsets is after a turn of `angle`, camera frame.
  Eigen::Vector3d position(const Eigen::Vector2d& offsets, double angle) const {
    return placed_.start + offsets.x() * placed_.direction +
           offsets.y() * (std::cos(angle) * e1_ + std::sin(angle) * e2_);
  }

  // The turns that put the marker nearest the ray through `normalised`: where the ray meets
  // the sphere the marker's circle lies on (enters and leaves it), brought onto the circle's
  // plane; the nearest point of the ray when it misses the sphere. Robust also when the ray
  // runs nearly along the circle's plane.
  std::vector<double> angles_towards(const Eigen::Vector2d& offsets,
                                     const Eigen::Vector2d& normalised) const {
    const Eigen::Vector3d ray(normalised.x(), normalised.y(), 1.0);
    const Eigen::Vector3d centre = placed_.start + offsets.x() * placed_.direction;
    const double a = ray.squaredNorm(), half_b = ray.dot(centre);
    const double c = centre.squaredNorm() - offsets.y() * offsets.y();
    const double discriminant = half_b * half_b - a * c;
    std::vector<double> depths;
    if (discriminant < 0) {
      depths.push_back(half_b / a);
    } else {
      depths.push_back((half_b - std::sqrt(discriminant)) / a);
      depths.push_back((half_b + std::sqrt(discriminant)) / a);
    }
    std::vector<double> angles;
    for (double depth : depths) {
      if (!(depth > 0)) continue;
      Eigen::Vector3d spoke = depth * ray - centre;
      spoke -= spoke.dot(placed_.direction) * placed_.direction;
      spoke /= offsets.y();
      angles.push_back(std::atan2(spoke.dot(e2_), spoke.dot(e1_)));
    }
    return angles;
  }

 private:
  const ConstellationModel& model_;
  const LineInSpace& placed_;
  LineAxes model_axes_;
  Eigen::Vector3d e1_, e2_;
};

std::optional<Eigen::Vector2d> to_normalised(const Eigen::Vector3d& point) {
  if (!(point.z() > 1e-6)) return std::nullopt;
  return Eigen::Vector2d(point.x() / point.z(), point.y() / point.z());
}

// A circle in the image, pixels.
struct ImageDisc {
  Eigen::Vector2d centre;
  double radius = 0;
};

// The votes of the free points within `reach` for the turn of `board` about its line: each
// pairs a marker off the line with a point that turn puts it on, within `tolerance_px`.
void collect_votes(const ConstellationModel& model, const ConstellationLine& line,
                   const BoardOnLine& board, const Candidate& candidate,
                   const std::vector<Eigen::Vector2d>& points, const std::vector<bool>& taken,
                   double focal, const ImageDisc& reach, double tolerance_px,
                   std::vector<Vote>& votes) {
  votes.clear();
  for (size_t m = 0; m < model.points.size(); ++m) {
    if (std::find(line.points.begin(), line.points.end(), static_cast<int>(m)) !=
        line.points.end()) {
      continue;
    }
    const Eigen::Vector2d offsets = board.offsets(static_cast<int>(m));
    if (std::abs(offsets.y()) < 1e-3) continue;  // on the line itself
    for (size_t i = 0; i < points.size(); ++i) {
      if (taken[i] || (points[i] - reach.centre).norm() > reach.radius) continue;
      if (std::find(candidate.points.begin(), candidate.points.end(), static_cast<int>(i)) !=
          candidate.points.end()) {
        continue;
      }
      for (double angle : board.angles_towards(offsets, points[i] / focal)) {
        auto at = to_normalised(board.position(offsets, angle));
        if (!at || (*at * focal - points[i]).norm() > tolerance_px) continue;
        votes.push_back({angle, static_cast<int>(m), static_cast<int>(i)});
      }
    }
  }
}

// Gives each marker `image_of` leaves unassigned (-1) the free point nearest where `homography`
// puts it, within `completion_px`; -1 where there is none.
void complete_with_homography(const ConstellationModel& model, const Eigen::Matrix3d& homography,
                              const std::vector<Eigen::Vector2d>& points,
                              const std::vector<bool>& taken, double completion_px,
                              std::vector<int>& image_of) {
  for (size_t m = 0; m < model.points.size(); ++m) {
    if (image_of[m] >= 0) continue;
    const Eigen::Vector2d at = apply_homography(homography, model.plane_points[m]);
    int nearest = -1;
    double nearest_distance = completion_px;
    for (size_t i = 0; i < points.size(); ++i) {
      if (taken[i]) continue;
      const double distance = (points[i] - at).norm();
      if (distance <= nearest_distance &&
          std::find(image_of.begin(), image_of.end(), static_cast<int>(i)) == image_of.end()) {
        nearest = static_cast<int>(i);
        nearest_distance = distance;
      }
    }
    image_of[m] = nearest;
  }
}

}  // namespace

std::optional<LineInSpace> place_line(const std::array<Eigen::Vector2d, 4>& normalised,
                                      const std::array<double, 4>& along_m) {
  // Marker k lies at depth λ_k on its ray r_k and at start + s_k·d on the line, start = λ_0·r_0:
  // λ_k·r_k − λ_0·r_0 − s_k·d = 0 for k = 1..3, nine equations, homogeneous in (λ_0..λ_3, d).
  // Their null vector, scaled to a unit d, is the line (the distances s_k fix the scale).
  Eigen::Matrix<double, 9, 7> system = Eigen::Matrix<double, 9, 7>::Zero();
  const Eigen::Vector3d first(normalised[0].x(), normalised[0].y(), 1.0);
  for (int k = 1; k < 4; ++k) {
    const int row = 3 * (k - 1);
    system.block<3, 1>(row, 0) = -first;
    system.block<3, 1>(row, k) = Eigen::Vector3d(normalised[k].x(), normalised[k].y(), 1.0);
    system.block<3, 3>(row, 4) = -along_m[k] * Eigen::Matrix3d::Identity();
  }
  Eigen::JacobiSVD<Eigen::Matrix<double, 9, 7>> svd(system, Eigen::ComputeFullV);
  Eigen::Matrix<double, 7, 1> solution = svd.matrixV().col(6);
  const double scale = solution.tail<3>().norm();
  if (!(scale > 1e-12)) return std::nullopt;
  solution /= scale;
  if (solution(0) < 0) solution = -solution;
  if (!(solution.head<4>().minCoeff() > 0)) return std::nullopt;  // every marker in front
  LineInSpace line;
  line.start = solution(0) * first;
  line.direction = solution.tail<3>();
  double sum = 0;
  for (int k = 0; k < 4; ++k) {
    auto seen = to_normalised(line.start + along_m[k] * line.direction);
    if (!seen) return std::nullopt;
    sum += (*seen - normalised[k]).squaredNorm();
  }
  line.rms_error = std::sqrt(sum / 4);
  return line;
}

// Kept whole (about 95 lines): every hypothesis (a line, a direction), its votes and the
// completions share the line's placement and the best board so far; the parts that stand
// alone are collect_votes and complete_with_homography.
std::optional<IdentifiedConstellation> find_from_one_line(
    const ConstellationModel& model, const std::vector<int>& type_of_line,
    const std::vector<std::vector<Candidate>>& by_type, const std::vector<Eigen::Vector2d>& points,
    const std::vector<bool>& taken, const IdentifierOptions& options, IdentificationStats& stats) {
  const double focal = options.focal_length_px;
  if (!(focal > 0) || options.min_loose_markers <= 0) return std::nullopt;
  // A turn named by one loose marker is only as good as the line's tilt in depth, which a
  // tenth of a pixel of noise on four collinear points changes visibly at the board's far end:
  // votes are taken within twice the plane fit's bound. Two of them and the line then fix the
  // homography, exact to a fraction of a pixel, and every further marker must land within a
  // third of the bound: that coincidence, not the votes, is the evidence.
  const double tolerance_px = 2 * options.max_fit_error_px;
  const double completion_px = options.max_fit_error_px / 3;
  std::optional<IdentifiedConstellation> best;
  std::vector<Vote> votes;
  std::vector<int> image_of;
  for (size_t l = 0; l < model.lines.size(); ++l) {
    const ConstellationLine& line = model.lines[l];
    std::array<double, 4> along{};
    for (int k = 0; k < 4; ++k) {
      along[k] = (model.points[line.points[k]] - model.points[line.points[0]]).norm();
    }
    double reach_m = 0;  // how far the board extends from the line's first marker
    for (const auto& p : model.points) {
      reach_m = std::max(reach_m, (p - model.points[line.points[0]]).norm());
    }
    for (const Candidate& candidate : by_type[type_of_line[l]]) {
      if (std::any_of(candidate.points.begin(), candidate.points.end(),
                      [&](int i) { return taken[i]; })) {
        continue;
      }
      for (bool reversed : {false, true}) {
        ++stats.one_line_hypotheses;
        const Choice choice{&candidate, reversed};
        std::array<Eigen::Vector2d, 4> seen;
        for (int k = 0; k < 4; ++k) seen[k] = points[choice.image_point(k)] / focal;
        auto placed = place_line(seen, along);
        if (!placed || placed->rms_error * focal > tolerance_px) continue;
        const BoardOnLine board(model, line, *placed);
        // Only points the board could reach are worth a vote.
        const double nearest_depth =
            std::min(placed->start.z(), (placed->start + along[3] * placed->direction).z()) -
            reach_m;
        const double radius_px = nearest_depth > 0.05 ? 1.5 * focal * reach_m / nearest_depth
                                                      : std::numeric_limits<double>::infinity();
        collect_votes(model, line, board, candidate, points, taken, focal,
                      {points[choice.image_point(0)], radius_px}, tolerance_px, votes);
        if (static_cast<int>(votes.size()) < 2) continue;
        // Two votes that agree on the turn, with the line, fix the plane's homography, exactly
        // and without the line's tilt; the markers it puts on free points complete the board.
        for (size_t first = 0; first < votes.size(); ++first) {
          for (size_t second = first + 1; second < votes.size(); ++second) {
            const Vote& a = votes[first];
            const Vote& b = votes[second];
            if (a.marker == b.marker || a.point == b.point ||
                std::abs(angle_difference(a.angle, b.angle)) > kMaxTurnDisagreement) {
              continue;
            }
            image_of.assign(model.points.size(), -1);
            for (int k = 0; k < 4; ++k) image_of[line.points[k]] = choice.image_point(k);
            image_of[a.marker] = a.point;
            image_of[b.marker] = b.point;
            auto seeded = plane_fit(model, image_of, points);
            if (!seeded || seeded->max > completion_px) continue;
            complete_with_homography(model, seeded->homography, points, taken, completion_px,
                                     image_of);
            const int identified = static_cast<int>(
                std::count_if(image_of.begin(), image_of.end(), [](int i) { return i >= 0; }));
            if (identified < 4 + options.min_loose_markers) continue;
            auto fit = plane_fit(model, image_of, points);
            if (!fit || fit->max > options.max_fit_error_px) {
              ++stats.rejected_by_fit;
              continue;
            }
            if (best &&
                (identified < best->points_identified() ||
                 (identified == best->points_identified() && fit->rms >= best->fit_rms_px))) {
              continue;
            }
            IdentifiedConstellation found;
            found.model = &model;
            found.image_point_of = image_of;
            IdentifiedLine whole;
            whole.model_line = static_cast<int>(l);
            whole.cross_ratio = candidate.cross_ratio;
            for (int k = 0; k < 4; ++k) whole.image_points[k] = choice.image_point(k);
            found.lines = {whole};
            found.fit_rms_px = fit->rms;
            found.fit_max_px = fit->max;
            found.from_one_line = true;
            best = std::move(found);
          }
        }
      }
    }
  }
  return best;
}

}  // namespace mocap::constellations
