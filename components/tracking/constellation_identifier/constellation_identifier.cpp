#include "tracking/constellation_identifier/constellation_identifier.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>

#include <fmt/format.h>

#include "tracking/constellation_database/cross_ratio.hpp"
#include "tracking/constellation_database/plane_homography.hpp"
#include "tracking/constellation_identifier/line_candidate.hpp"
#include "tracking/constellation_identifier/one_line_search.hpp"

namespace mocap::constellations {

std::optional<PlaneFit> plane_fit(const ConstellationModel& model, const std::vector<int>& image_of,
                                  const std::vector<Eigen::Vector2d>& points) {
  // The searches fit thousands of hypotheses a frame: the pairs stay on the stack for boards
  // of up to 64 markers.
  constexpr size_t kOnStack = 64;
  std::array<Eigen::Vector2d, kOnStack> from_stack, to_stack;
  std::vector<Eigen::Vector2d> from_heap, to_heap;
  const bool small = image_of.size() <= kOnStack;
  if (!small) {
    from_heap.resize(image_of.size());
    to_heap.resize(image_of.size());
  }
  Eigen::Vector2d* from_data = small ? from_stack.data() : from_heap.data();
  Eigen::Vector2d* to_data = small ? to_stack.data() : to_heap.data();
  size_t count = 0;
  for (size_t m = 0; m < image_of.size(); ++m) {
    if (image_of[m] < 0) continue;
    from_data[count] = model.plane_points[m];
    to_data[count] = points[image_of[m]];
    ++count;
  }
  const std::span<const Eigen::Vector2d> from(from_data, count), to(to_data, count);
  auto h = fit_homography(from, to);
  if (!h) return std::nullopt;
  double nearest = std::numeric_limits<double>::infinity(), farthest = -nearest;
  for (const auto& p : model.plane_points) {
    const double depth = h->row(2).dot(Eigen::Vector3d(p.x(), p.y(), 1.0));
    nearest = std::min(nearest, depth);
    farthest = std::max(farthest, depth);
  }
  if (nearest < 0) {  // the same board, seen from the other side of its plane's horizon
    std::swap(nearest, farthest);
    nearest = -nearest;
    farthest = -farthest;
  }
  if (!(nearest > 0) || farthest > kMaxDepthRatio * nearest) return std::nullopt;
  PlaneFit fit;
  fit.homography = *h;
  for (size_t i = 0; i < from.size(); ++i) {
    double e = (apply_homography(*h, from[i]) - to[i]).norm();
    fit.rms += e * e;
    fit.max = std::max(fit.max, e);
  }
  fit.rms = std::sqrt(fit.rms / static_cast<double>(from.size()));
  return fit;
}

namespace {

// A line type's candidates read both ways, and per position k the choices grouped by the
// image point they put there (counting sort: choice ids by point, in increasing choice order):
// built once a frame and shared by every constellation with a line of that type.
struct TypeChoices {
  std::vector<Choice> choices;
  std::array<std::vector<int>, 4> first;  // per k, per image point: offset into `by_point`
  std::array<std::vector<int>, 4> by_point;

  TypeChoices(const std::vector<Candidate>& candidates, size_t points) {
    for (const Candidate& candidate : candidates) {
      choices.push_back({&candidate, false});
      choices.push_back({&candidate, true});
    }
    for (int k = 0; k < 4; ++k) {
      first[k].assign(points + 1, 0);
      for (const Choice& choice : choices) ++first[k][choice.image_point(k) + 1];
      for (size_t p = 0; p < points; ++p) first[k][p + 1] += first[k][p];
      by_point[k].resize(choices.size());
      std::vector<int> next(first[k].begin(), first[k].end() - 1);
      for (size_t c = 0; c < choices.size(); ++c) {
        by_point[k][next[choices[c].image_point(k)]++] = static_cast<int>(c);
      }
    }
  }

  // The choices whose image point at position k is `point`.
  std::span<const int> holding(int k, int point) const {
    return {by_point[k].data() + first[k][point],
            static_cast<size_t>(first[k][point + 1] - first[k][point])};
  }
  // Every choice, in the order of the image point they put at position 0.
  std::span<const int> all() const { return by_point[0]; }
};

// Finds one constellation among the candidates: hypothesise from two lines that share a
// marker (seven points fix a plane-to-image homography), then extend by the remaining lines
// whose candidates land where that homography puts them. Two linked lines are selective
// (the second candidate must hold the very image point the first put at the shared marker),
// so few hypotheses survive to the plane fit, also with several boards and distractors.
class ConstellationSearch {
 public:
  ConstellationSearch(const ConstellationModel& model, const std::vector<int>& type_of_line,
                      const std::vector<TypeChoices>& by_type,
                      const std::vector<Eigen::Vector2d>& points, const IdentifierOptions& options)
      : model_(model),
        type_of_line_(type_of_line),
        by_type_(by_type),
        points_(points),
        options_(options),
        min_lines_(std::min<int>(options.min_lines, static_cast<int>(model.lines.size()))),
        search_min_lines_(options.min_extra_markers > 0 ? std::min(min_lines_, 2) : min_lines_),
        image_of_(model.points.size(), -1),
        chosen_(model.lines.size()) {}

  std::optional<IdentifiedConstellation> search(IdentificationStats& stats) {
    stats_ = &stats;
    const size_t lines = model_.lines.size();
    if (lines == 1) {
      for (const Choice& first : choices(0)) {
        if (!assign(0, first)) continue;
        extend_and_evaluate();
        release(0);
      }
    }
    // Seeds from linked pairs; pairs without a shared marker only when the model has no
    // linked pair at all (two separate lines leave the homography underdetermined).
    bool linked = false;
    for (size_t a = 0; a < lines; ++a) {
      for (size_t b = a + 1; b < lines; ++b) linked = linked || shared_marker(a, b);
    }
    for (size_t a = 0; a < lines && !complete_; ++a) {
      for (size_t b = a + 1; b < lines; ++b) {
        auto shared = shared_marker(a, b);
        if (linked && !shared) continue;
        for (size_t f = 0; f < choices(a).size() && !complete_; ++f) {
          const Choice& first = choices(a)[f];
          if (!assign(a, first)) continue;
          std::span<const int> seconds = index(b).all();
          if (shared) seconds = index(b).holding(shared->second, first.image_point(shared->first));
          for (auto it = seconds.begin(); it != seconds.end() && !complete_; ++it) {
            if (!assign(b, choices(b)[*it])) continue;
            extend_and_evaluate();
            release(b);
          }
          release(a);
        }
      }
    }
    if (best_count_ == 0) return std::nullopt;
    int extra = complete_with_markers();
    if (best_count_ < min_lines_ && extra < options_.min_extra_markers) return std::nullopt;
    IdentifiedConstellation found;
    found.model = &model_;
    found.image_point_of = best_image_of_;
    found.lines = best_lines_;
    found.fit_rms_px = best_fit_.rms;
    found.fit_max_px = best_fit_.max;
    return found;
  }

 private:
  // Adds the unseen markers that an image point lies on, where the plane of the best
  // assignment puts them (the nearest within a third of max_fit_error_px: the prediction from
  // whole lines is good to a fraction of a pixel, and a tight radius keeps stray points from
  // confirming a chance pair of lines); returns how many.
  int complete_with_markers() {
    auto fit = plane_fit(model_, best_image_of_, points_);
    if (!fit) return 0;
    const std::vector<int> before = best_image_of_;
    int added = 0;
    for (size_t m = 0; m < best_image_of_.size(); ++m) {
      if (best_image_of_[m] >= 0) continue;
      Eigen::Vector2d predicted = apply_homography(fit->homography, model_.plane_points[m]);
      int nearest = -1;
      double nearest_distance = options_.max_fit_error_px / 3;
      for (size_t i = 0; i < points_.size(); ++i) {
        double distance = (points_[i] - predicted).norm();
        if (distance <= nearest_distance &&
            std::find(best_image_of_.begin(), best_image_of_.end(), static_cast<int>(i)) ==
                best_image_of_.end()) {
          nearest = static_cast<int>(i);
          nearest_distance = distance;
        }
      }
      if (nearest >= 0) {
        best_image_of_[m] = nearest;
        ++added;
      }
    }
    if (added > 0) {
      // Markers the whole cannot explain together are strays after all.
      auto refit = plane_fit(model_, best_image_of_, points_);
      if (!refit || refit->max > options_.max_fit_error_px) {
        best_image_of_ = before;
        return 0;
      }
      best_fit_ = *refit;
    }
    return added;
  }

  // Positions (in line a, in line b) of a marker both lines hold, if any.
  std::optional<std::pair<int, int>> shared_marker(size_t a, size_t b) const {
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        if (model_.lines[a].points[i] == model_.lines[b].points[j]) return std::make_pair(i, j);
      }
    }
    return std::nullopt;
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

  // Adds every other line whose candidate lies where the plane of the lines chosen so far
  // puts it, then scores the whole.
  void extend_and_evaluate() {
    std::vector<size_t> added;
    std::optional<PlaneFit> fit;
    bool stale = false;  // the fit predates lines added since
    for (size_t line = 0; line < model_.lines.size(); ++line) {
      if (chosen_[line].candidate != nullptr) continue;
      const ConstellationLine& model_line = model_.lines[line];
      // A marker of this line already placed narrows the choices to those holding it.
      std::span<const int> range = index(line).all();
      for (int k = 0; k < 4; ++k) {
        if (image_of_[model_line.points[k]] >= 0) {
          range = index(line).holding(k, image_of_[model_line.points[k]]);
          break;
        }
      }
      if (range.empty()) continue;
      // The plane of the lines so far predicts this one; a fit that has not seen the lines
      // added since is refitted only when it finds nothing (a refit costs more than a look).
      const Choice* best = nullptr;
      for (bool retry : {false, true}) {
        if (retry && !stale) break;
        if (!fit || retry) {
          fit = plane_fit(model_, image_of_, points_);
          stale = false;
        }
        if (!fit) break;
        std::array<Eigen::Vector2d, 4> predicted;
        for (int k = 0; k < 4; ++k) {
          predicted[k] =
              apply_homography(fit->homography, model_.plane_points[model_line.points[k]]);
        }
        // The candidate whose points lie closest to where the plane puts this line.
        double best_error = options_.max_fit_error_px;
        for (int c : range) {
          const Choice& choice = choices(line)[c];
          double error = 0;
          for (int k = 0; k < 4 && error <= best_error; ++k) {
            error = std::max(error, (predicted[k] - points_[choice.image_point(k)]).norm());
          }
          if (error <= best_error) {
            best_error = error;
            best = &choice;
          }
        }
        if (best != nullptr) break;
      }
      if (!fit) break;
      if (best != nullptr && assign(line, *best)) {
        added.push_back(line);
        stale = true;
      }
    }
    evaluate();
    for (auto it = added.rbegin(); it != added.rend(); ++it) release(*it);
  }

  void evaluate() {
    int count = static_cast<int>(
        std::count_if(chosen_.begin(), chosen_.end(), [](const Choice& c) { return c.candidate; }));
    if (count < search_min_lines_ || count < best_count_) return;
    auto fit = plane_fit(model_, image_of_, points_);
    if (!fit || fit->max > options_.max_fit_error_px) {
      ++stats_->rejected_by_fit;
      return;
    }
    if (count == best_count_ && fit->rms >= best_fit_.rms) return;
    // Every line found and on one plane: another seed would find the same points.
    complete_ = count == static_cast<int>(model_.lines.size());
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
  const std::vector<TypeChoices>& by_type_;
  const std::vector<Eigen::Vector2d>& points_;
  const IdentifierOptions& options_;
  const int min_lines_;
  const int search_min_lines_;  // fewer whole lines may do when extra markers confirm them
  IdentificationStats* stats_ = nullptr;
  std::vector<int> image_of_;
  std::vector<Choice> chosen_;
  // Per line: every candidate of its type, both directions, and the index by position.
  const TypeChoices& index(size_t line) const { return by_type_[type_of_line_[line]]; }
  const std::vector<Choice>& choices(size_t line) const { return index(line).choices; }
  int best_count_ = 0;
  bool complete_ = false;
  PlaneFit best_fit_;
  std::vector<int> best_image_of_;
  std::vector<IdentifiedLine> best_lines_;
};

// Four-point candidates in order along each group (from at most `window` consecutive points),
// sorted into line types by cross-ratio: per type, those within `tolerance` of
// `type_ratios[type]`.
std::vector<std::vector<Candidate>> candidates_by_type(const std::vector<Eigen::Vector2d>& points,
                                                       const std::vector<CollinearGroup>& groups,
                                                       const std::vector<double>& type_ratios,
                                                       int window, double tolerance,
                                                       IdentificationStats& s) {
  std::vector<std::vector<Candidate>> by_type(type_ratios.size());
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
            for (size_t t = 0; t < type_ratios.size(); ++t) {
              if (relative_difference(candidate.cross_ratio, type_ratios[t]) <= tolerance) {
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
  return by_type;
}

// The boards found from one line, best first, without those that explain the same points as
// well as another: boards of one size hinged on a side of one line type share their corners,
// and neither can be told from the other, so neither is named (counted as conflicts).
std::vector<IdentifiedConstellation> unambiguous(std::vector<IdentifiedConstellation> found,
                                                 IdentificationStats& s) {
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    if (a.points_identified() != b.points_identified()) {
      return a.points_identified() > b.points_identified();
    }
    return a.fit_rms_px < b.fit_rms_px;
  });
  std::vector<bool> ambiguous(found.size(), false);
  for (size_t a = 0; a < found.size(); ++a) {
    for (size_t b = a + 1; b < found.size(); ++b) {
      const auto& first = found[a].image_point_of;
      const auto& second = found[b].image_point_of;
      if (found[a].points_identified() != found[b].points_identified()) continue;
      bool overlap = std::any_of(first.begin(), first.end(), [&](int i) {
        return i >= 0 && std::find(second.begin(), second.end(), i) != second.end();
      });
      if (overlap) ambiguous[a] = ambiguous[b] = true;
    }
  }
  std::vector<IdentifiedConstellation> clear;
  for (size_t k = 0; k < found.size(); ++k) {
    if (ambiguous[k]) {
      ++s.conflicts;
    } else {
      clear.push_back(std::move(found[k]));
    }
  }
  return clear;
}

}  // namespace

int IdentifiedConstellation::points_identified() const {
  return static_cast<int>(
      std::count_if(image_point_of.begin(), image_point_of.end(), [](int i) { return i >= 0; }));
}

std::optional<std::string> IdentifierOptions::problem() const {
  if (auto problem = line_search.problem()) return "line_search." + *problem;
  if (!(cross_ratio_tolerance > 0)) {
    return fmt::format("cross_ratio_tolerance: {} is not above 0", cross_ratio_tolerance);
  }
  if (min_lines < 1) return fmt::format("min_lines: {} is below 1", min_lines);
  if (min_extra_markers < 0) {
    return fmt::format("min_extra_markers: {} is below 0", min_extra_markers);
  }
  if (!(max_fit_error_px > 0)) {
    return fmt::format("max_fit_error_px: {} is not above 0", max_fit_error_px);
  }
  if (candidate_window < 4) {
    return fmt::format("candidate_window: {}; a line's four points need four at least",
                       candidate_window);
  }
  if (!(focal_length_px >= 0)) {
    return fmt::format("focal_length_px: {} is below 0", focal_length_px);
  }
  if (min_loose_markers < 0) {
    return fmt::format("min_loose_markers: {} is below 0", min_loose_markers);
  }
  return std::nullopt;
}

ConstellationIdentifier::ConstellationIdentifier(const ConstellationDatabase& database,
                                                 IdentifierOptions options)
    : database_(database), options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("IdentifierOptions::" + *problem);
  }
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

  std::vector<double> type_ratios;
  for (const LineType& type : line_types_) type_ratios.push_back(type.cross_ratio);
  const std::vector<std::vector<Candidate>> by_type = candidates_by_type(
      points, groups, type_ratios, options_.candidate_window, options_.cross_ratio_tolerance, s);

  std::vector<TypeChoices> choices_by_type;
  choices_by_type.reserve(by_type.size());
  for (const auto& candidates : by_type) choices_by_type.emplace_back(candidates, points.size());
  std::vector<IdentifiedConstellation> found;
  const auto& models = database_.constellations();
  for (size_t m = 0; m < models.size(); ++m) {
    ConstellationSearch search(models[m], line_type_of_[m], choices_by_type, points, options_);
    if (auto result = search.search(s)) found.push_back(std::move(*result));
  }
  // Most lines first, then most markers, then the best fit; a constellation whose points a
  // better one took is a misreading of that one.
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    if (a.lines.size() != b.lines.size()) return a.lines.size() > b.lines.size();
    if (a.points_identified() != b.points_identified()) {
      return a.points_identified() > b.points_identified();
    }
    return a.fit_rms_px < b.fit_rms_px;
  });
  std::vector<bool> taken(points.size(), false);
  std::vector<IdentifiedConstellation> accepted;
  auto accept_free = [&](std::vector<IdentifiedConstellation>& candidates) {
    for (auto& candidate : candidates) {
      bool free = std::none_of(candidate.image_point_of.begin(), candidate.image_point_of.end(),
                               [&](int i) { return i >= 0 && taken[i]; });
      if (!free) {
        ++s.conflicts;
        continue;
      }
      for (int i : candidate.image_point_of) {
        if (i >= 0) taken[i] = true;
      }
      accepted.push_back(std::move(candidate));
    }
  };
  accept_free(found);
  // Constellations not found by two or more lines may show one whole line and loose markers.
  if (options_.focal_length_px > 0 && options_.min_loose_markers > 0) {
    std::vector<IdentifiedConstellation> from_one_line;
    for (size_t m = 0; m < models.size(); ++m) {
      bool known = std::any_of(accepted.begin(), accepted.end(),
                               [&](const auto& a) { return a.model == &models[m]; });
      if (known) continue;
      if (auto result = find_from_one_line(models[m], line_type_of_[m], by_type, points, taken,
                                           options_, s)) {
        from_one_line.push_back(std::move(*result));
      }
    }
    std::vector<IdentifiedConstellation> clear = unambiguous(std::move(from_one_line), s);
    accept_free(clear);
  }
  for (auto& constellation : accepted) {
    for (int& i : constellation.image_point_of) {
      if (i >= 0) i = input_index[i];
    }
    for (IdentifiedLine& line : constellation.lines) {
      for (int& i : line.image_points) i = input_index[i];
    }
  }
  return accepted;
}

}  // namespace mocap::constellations
