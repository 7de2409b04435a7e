#include "constellation_identifier.hpp"

#include <algorithm>
#include <cmath>

#include "cross_ratio.hpp"
#include "plane_homography.hpp"

namespace mocap::constellations {
namespace {

struct Candidate {
  std::array<int, 4> points;  // along the image line
  double cross_ratio;
};

struct Fit {
  double rms = 0;
  double max = 0;
};

// How well one plane-to-image homography explains the assigned points.
std::optional<Fit> plane_fit(const ConstellationModel& model, const std::vector<int>& image_of,
                             const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> from, to;
  for (size_t m = 0; m < image_of.size(); ++m) {
    if (image_of[m] < 0) continue;
    from.push_back(model.plane_points[m]);
    to.push_back(points[image_of[m]]);
  }
  auto h = fit_homography(from, to);
  if (!h) return std::nullopt;
  Fit fit;
  for (size_t i = 0; i < from.size(); ++i) {
    double e = (apply_homography(*h, from[i]) - to[i]).norm();
    fit.rms += e * e;
    fit.max = std::max(fit.max, e);
  }
  fit.rms = std::sqrt(fit.rms / static_cast<double>(from.size()));
  return fit;
}

std::optional<Eigen::Matrix3d> plane_homography(const ConstellationModel& model,
                                                const std::vector<int>& image_of,
                                                const std::vector<Eigen::Vector2d>& points) {
  std::vector<Eigen::Vector2d> from, to;
  for (size_t m = 0; m < image_of.size(); ++m) {
    if (image_of[m] < 0) continue;
    from.push_back(model.plane_points[m]);
    to.push_back(points[image_of[m]]);
  }
  return fit_homography(from, to);
}

// Finds one constellation among the candidates: hypothesise from two lines that share a
// marker (seven points fix a plane-to-image homography), then extend by the remaining lines
// whose candidates land where that homography puts them. Two linked lines are selective
// (the second candidate must hold the very image point the first put at the shared marker),
// so few hypotheses survive to the plane fit, also with several boards and distractors.
class ConstellationSearch {
 public:
  ConstellationSearch(const ConstellationModel& model, const std::vector<int>& type_of_line,
                      const std::vector<std::vector<Candidate>>& by_type,
                      const std::vector<Eigen::Vector2d>& points, const IdentifierOptions& options)
      : model_(model),
        type_of_line_(type_of_line),
        by_type_(by_type),
        points_(points),
        options_(options),
        min_lines_(std::min<int>(options.min_lines, static_cast<int>(model.lines.size()))),
        image_of_(model.points.size(), -1),
        chosen_(model.lines.size()) {}

  std::optional<IdentifiedConstellation> search(IdentificationStats& stats) {
    stats_ = &stats;
    const size_t lines = model_.lines.size();
    if (lines == 1) {
      for (const Choice& first : choices(0)) try_seed({{0, first}});
    }
    // Seeds from linked pairs first; pairs without a shared marker only when the model has
    // no linked pair at all (two separate lines leave the homography underdetermined).
    bool linked = false;
    for (size_t a = 0; a < lines; ++a) {
      for (size_t b = a + 1; b < lines; ++b) linked = linked || shared_marker(a, b);
    }
    for (size_t a = 0; a < lines && best_count_ < static_cast<int>(lines); ++a) {
      for (size_t b = a + 1; b < lines; ++b) {
        if (linked && !shared_marker(a, b)) continue;
        for (const Choice& first : choices(a)) {
          if (!assign(a, first)) continue;
          for (const Choice& second : choices(b)) {
            if (!assign(b, second)) continue;
            extend_and_evaluate();
            release(b);
          }
          release(a);
        }
      }
    }
    if (best_count_ == 0) return std::nullopt;
    IdentifiedConstellation found;
    found.model = &model_;
    found.image_point_of = best_image_of_;
    found.lines = best_lines_;
    found.fit_rms_px = best_fit_.rms;
    found.fit_max_px = best_fit_.max;
    return found;
  }

 private:
  struct Choice {
    const Candidate* candidate = nullptr;
    bool reversed = false;
    int image_point(int k) const { return candidate->points[reversed ? 3 - k : k]; }
  };

  std::vector<Choice> choices(size_t line) const {
    std::vector<Choice> out;
    for (const Candidate& candidate : by_type_[type_of_line_[line]]) {
      out.push_back({&candidate, false});
      out.push_back({&candidate, true});
    }
    return out;
  }

  bool shared_marker(size_t a, size_t b) const {
    for (int p : model_.lines[a].points) {
      for (int q : model_.lines[b].points) {
        if (p == q) return true;
      }
    }
    return false;
  }

  void try_seed(std::initializer_list<std::pair<size_t, Choice>> seed) {
    for (const auto& [line, choice] : seed) {
      if (!assign(line, choice)) return;
    }
    extend_and_evaluate();
    for (const auto& [line, choice] : seed) release(line);
  }

  // Maps a line's markers to a choice's image points, unless that contradicts a marker
  // already mapped or uses an image point another marker has.
  bool assign(size_t line, const Choice& choice) {
    const ConstellationLine& model_line = model_.lines[line];
    for (int k = 0; k < 4; ++k) {
      int marker = model_line.points[k];
      int image_point = choice.image_point(k);
      if (image_of_[marker] >= 0) {
        if (image_of_[marker] != image_point) return false;
      } else if (std::find(image_of_.begin(), image_of_.end(), image_point) != image_of_.end()) {
        return false;
      }
    }
    chosen_[line] = choice;
    for (int k = 0; k < 4; ++k) image_of_[model_line.points[k]] = choice.image_point(k);
    return true;
  }

  // Undoes assign(): a marker stays mapped while another chosen line holds it.
  void release(size_t line) {
    chosen_[line] = {};
    for (int marker : model_.lines[line].points) {
      bool held = false;
      for (size_t other = 0; other < chosen_.size(); ++other) {
        if (chosen_[other].candidate == nullptr) continue;
        for (int p : model_.lines[other].points) held = held || p == marker;
      }
      if (!held) image_of_[marker] = -1;
    }
  }

  void extend_and_evaluate() {
    auto fit = plane_fit(model_, image_of_, points_);
    if (!fit || fit->max > options_.max_fit_error_px) {
      ++stats_->rejected_by_fit;
      return;
    }
    std::vector<size_t> added;
    for (size_t line = 0; line < model_.lines.size(); ++line) {
      if (chosen_[line].candidate != nullptr) continue;
      auto h = plane_homography(model_, image_of_, points_);
      if (!h) break;
      // The candidate whose points lie closest to where the plane puts this line.
      const ConstellationLine& model_line = model_.lines[line];
      double best_error = options_.max_fit_error_px;
      std::optional<Choice> best;
      for (const Choice& choice : choices(line)) {
        double error = 0;
        for (int k = 0; k < 4 && error <= best_error; ++k) {
          Eigen::Vector2d predicted =
              apply_homography(*h, model_.plane_points[model_line.points[k]]);
          error = std::max(error, (predicted - points_[choice.image_point(k)]).norm());
        }
        if (error <= best_error) {
          best_error = error;
          best = choice;
        }
      }
      if (best && assign(line, *best)) added.push_back(line);
    }
    evaluate();
    for (auto it = added.rbegin(); it != added.rend(); ++it) release(*it);
  }

  void evaluate() {
    int count = static_cast<int>(
        std::count_if(chosen_.begin(), chosen_.end(), [](const Choice& c) { return c.candidate; }));
    if (count < min_lines_ || count < best_count_) return;
    auto fit = plane_fit(model_, image_of_, points_);
    if (!fit || fit->max > options_.max_fit_error_px) {
      ++stats_->rejected_by_fit;
      return;
    }
    if (count == best_count_ && fit->rms >= best_fit_.rms) return;
    best_count_ = count;
    best_fit_ = *fit;
    best_image_of_ = image_of_;
    best_lines_.clear();
    for (size_t l = 0; l < chosen_.size(); ++l) {
      if (chosen_[l].candidate == nullptr) continue;
      IdentifiedLine identified;
      identified.model_line = static_cast<int>(l);
      identified.cross_ratio = chosen_[l].candidate->cross_ratio;
      for (int k = 0; k < 4; ++k) identified.image_points[k] = chosen_[l].image_point(k);
      best_lines_.push_back(identified);
    }
  }

  const ConstellationModel& model_;
  const std::vector<int>& type_of_line_;
  const std::vector<std::vector<Candidate>>& by_type_;
  const std::vector<Eigen::Vector2d>& points_;
  const IdentifierOptions& options_;
  const int min_lines_;
  IdentificationStats* stats_ = nullptr;
  std::vector<int> image_of_;
  std::vector<Choice> chosen_;
  int best_count_ = 0;
  Fit best_fit_;
  std::vector<int> best_image_of_;
  std::vector<IdentifiedLine> best_lines_;
};

}  // namespace

int IdentifiedConstellation::points_identified() const {
  return static_cast<int>(
      std::count_if(image_point_of.begin(), image_point_of.end(), [](int i) { return i >= 0; }));
}

ConstellationIdentifier::ConstellationIdentifier(const ConstellationDatabase& database,
                                                 IdentifierOptions options)
    : database_(database), options_(options) {
  for (const ConstellationModel& model : database_.constellations()) {
    std::vector<int> types;
    for (const ConstellationLine& line : model.lines) {
      auto known = std::find_if(line_types_.begin(), line_types_.end(),
                                [&](const LineType& type) { return type.name == line.name; });
      if (known == line_types_.end()) {
        line_types_.push_back({line.name, line.cross_ratio});
        known = line_types_.end() - 1;
      }
      types.push_back(static_cast<int>(known - line_types_.begin()));
    }
    line_type_of_.push_back(std::move(types));
  }
}

std::vector<IdentifiedConstellation> ConstellationIdentifier::identify(
    const std::vector<Eigen::Vector2d>& input, IdentificationStats* stats) const {
  IdentificationStats local;
  IdentificationStats& s = stats ? *stats : local;
  s = {};
  // Non-finite points would poison every line through them; the search runs on the finite
  // ones and results are mapped back to the caller's indices.
  std::vector<Eigen::Vector2d> points;
  std::vector<int> input_index;
  for (size_t i = 0; i < input.size(); ++i) {
    if (!input[i].allFinite()) continue;
    points.push_back(input[i]);
    input_index.push_back(static_cast<int>(i));
  }
  std::vector<CollinearGroup> groups = find_collinear_groups(points, options_.line_search);
  s.groups = groups.size();

  // Four-point candidates in order along each group, sorted into line types by cross-ratio.
  std::vector<std::vector<Candidate>> by_type(line_types_.size());
  const int window = std::max(4, options_.candidate_window);
  for (const CollinearGroup& group : groups) {
    const auto& g = group.points;
    const int n = static_cast<int>(g.size());
    for (int a = 0; a + 3 < n; ++a) {
      int end = std::min(n, a + window);
      for (int b = a + 1; b < end; ++b) {
        for (int c = b + 1; c < end; ++c) {
          for (int d = c + 1; d < end; ++d) {
            ++s.candidates;
            Candidate candidate{{g[a], g[b], g[c], g[d]}, 0};
            candidate.cross_ratio =
                cross_ratio(points[g[a]], points[g[b]], points[g[c]], points[g[d]]);
            bool matched = false;
            for (size_t t = 0; t < line_types_.size(); ++t) {
              if (relative_difference(candidate.cross_ratio, line_types_[t].cross_ratio) <=
                  options_.cross_ratio_tolerance) {
                by_type[t].push_back(candidate);
                matched = true;
              }
            }
            s.matched += matched;
          }
        }
      }
    }
  }

  std::vector<IdentifiedConstellation> found;
  const auto& models = database_.constellations();
  for (size_t m = 0; m < models.size(); ++m) {
    ConstellationSearch search(models[m], line_type_of_[m], by_type, points, options_);
    if (auto result = search.search(s)) found.push_back(std::move(*result));
  }
  // Most lines first, then the best fit; a constellation whose points a better one took is
  // a misreading of that one.
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    if (a.lines.size() != b.lines.size()) return a.lines.size() > b.lines.size();
    return a.fit_rms_px < b.fit_rms_px;
  });
  std::vector<bool> taken(points.size(), false);
  std::vector<IdentifiedConstellation> accepted;
  for (auto& candidate : found) {
    bool free = std::none_of(candidate.image_point_of.begin(), candidate.image_point_of.end(),
                             [&](int i) { return i >= 0 && taken[i]; });
    if (!free) {
      ++s.conflicts;
      continue;
    }
    for (int& i : candidate.image_point_of) {
      if (i < 0) continue;
      taken[i] = true;
      i = input_index[i];
    }
    for (IdentifiedLine& line : candidate.lines) {
      for (int& i : line.image_points) i = input_index[i];
    }
    accepted.push_back(std::move(candidate));
  }
  return accepted;
}

}  // namespace mocap::constellations
