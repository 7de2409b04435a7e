#include "tracking/fiducial_tracker/fiducial_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include <opencv2/core.hpp>
#include <opencv2/core/hal/intrin.hpp>

namespace mocap::tracking {
namespace {

// The brightest pixel of a row. OpenCV's universal intrinsics keep this one pass over the
// frame at 16 (SSE2, NEON) or more pixels per instruction on any target; without SIMD it is a
// plain loop.
uint8_t row_peak(const uint8_t* row, int width) {
  int x = 0;
  uint8_t peak = 0;
#if CV_SIMD
  constexpr int kLanes = cv::v_uint8::nlanes;
  if (width >= kLanes) {
    cv::v_uint8 lanes = cv::vx_setzero_u8();
    for (; x + kLanes <= width; x += kLanes) lanes = cv::v_max(lanes, cv::vx_load(row + x));
    peak = cv::v_reduce_max(lanes);
  }
#endif
  for (; x < width; ++x) peak = std::max(peak, row[x]);
  return peak;
}

// The first x in [x, width) with row[x] >= level, or width. Dark stretches are skipped a SIMD
// register at a time; level is in [1, 255].
int next_bright_pixel(const uint8_t* row, int x, int width, int level) {
#if CV_SIMD
  constexpr int kLanes = cv::v_uint8::nlanes;
  const cv::v_uint8 threshold = cv::vx_setall_u8(static_cast<uint8_t>(level));
  while (x + kLanes <= width && !cv::v_check_any(cv::vx_load(row + x) >= threshold)) x += kLanes;
#endif
  while (x < width && row[x] < level) ++x;
  return x;
}

// Σ k² for k = 0..n (0 for n < 0).
int64_t sum_of_squares(int64_t n) { return n < 0 ? 0 : n * (n + 1) * (2 * n + 1) / 6; }

// var(x̂) = σ² Σ (xᵢ - x̂)² / W² for the centroid x̂ = Σ wᵢxᵢ / W of pixels with independent
// noise σ; Σ (xᵢ - x̂)² comes from plain sums (n, Σx, Σx²), clamped against rounding.
double centroid_sigma(double noise, double weight, double n, double x, double sum_x, double sum_xx,
                      double y, double sum_y, double sum_yy) {
  const double spread_x = std::max(0.0, sum_xx - 2 * x * sum_x + n * x * x);
  const double spread_y = std::max(0.0, sum_yy - 2 * y * sum_y + n * y * y);
  return noise * std::sqrt((spread_x + spread_y) / 2) / weight;
}

// How much more a threshold-only centroid keeps of the pixel grid than a windowed one
// (FiducialDetectorOptions::sampling_error_px): 0.19 against 0.06 px·sqrt(pixels) on the
// volume demo's images.
constexpr double kThresholdOnlySampling = 3;

// Regions whose bounding box holds more pixels than this are not outlined when their size
// alone rules them out as round (see circularity()).
constexpr int64_t kLargestOutlinedBox = 1 << 16;

// The length and twice the area of the outline where `values` (a patch of `height` rows of
// `stride`) crosses zero, by marching squares (FiducialDetector::circularity says how).
struct Outline {
  double length = 0, twice_area = 0;
};
Outline outline_of_patch(const float* values, int stride, int patch_height, bool join_diagonals) {
  double length = 0, twice_area = 0;
  // Adds the segment p-q, oriented so that `reference` lies on its right if
  // `reference_inside`, on its left otherwise (y down: right of east is south).
  auto add_segment = [&](cv::Point2d p, cv::Point2d q, cv::Point2d reference,
                         bool reference_inside) {
    const double side = (q.x - p.x) * (reference.y - p.y) - (q.y - p.y) * (reference.x - p.x);
    if ((side > 0) != reference_inside) std::swap(p, q);
    // sqrt, not std::hypot: hypot guards against overflow at several times the cost.
    length += std::sqrt((q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y));
    twice_area += p.x * q.y - q.x * p.y;
  };
  for (int py = 0; py + 1 < patch_height; ++py) {
    const float* upper = values + static_cast<size_t>(py) * stride;
    const float* lower = upper + stride;
    for (int px = 0; px + 1 < stride; ++px) {
      // Corners clockwise from the top left, in patch coordinates.
      const float value[4] = {upper[px], upper[px + 1], lower[px + 1], lower[px]};
      const int inside = (value[0] > 0 ? 1 : 0) | (value[1] > 0 ? 2 : 0) | (value[2] > 0 ? 4 : 0) |
                         (value[3] > 0 ? 8 : 0);
      if (inside == 0 || inside == 15) continue;
      const cv::Point2d corner[4] = {{double(px), double(py)},
                                     {px + 1.0, double(py)},
                                     {px + 1.0, py + 1.0},
                                     {double(px), py + 1.0}};
      // Where edge e (corner e to corner e+1) crosses zero, for edges whose ends differ.
      auto crossing = [&](int e) {
        const int a = e, b = (e + 1) & 3;
        const double t = value[a] / (value[a] - value[b]);
        return corner[a] + t * (corner[b] - corner[a]);
      };
      auto is_inside = [&](int c) { return (inside >> c & 1) != 0; };
      if (inside == 5 || inside == 10) {
        // Saddle: cut off the two corners that are not joined across the cell.
        const bool cut_outside = join_diagonals;
        for (int c = 0; c < 4; ++c) {
          if (is_inside(c) == cut_outside) continue;
          // Corner c lies between edges c-1 and c.
          add_segment(crossing((c + 3) & 3), crossing(c), corner[c], is_inside(c));
        }
        continue;
      }
      // One segment between the two edges whose ends differ.
      int edges[2], found = 0, reference = 0;
      for (int e = 0; e < 4; ++e) {
        if (is_inside(e) != is_inside((e + 1) & 3)) edges[found++] = e;
        if (is_inside(e)) reference = e;
      }
      add_segment(crossing(edges[0]), crossing(edges[1]), corner[reference], true);
    }
  }
  return {length, twice_area};
}

}  // namespace

std::optional<std::string> FiducialDetectorOptions::problem() const {
  auto outside = [](double value, double low, double high) {
    return !(value >= low && value <= high);
  };
  if (outside(threshold_ratio, 0, 1)) {
    return fmt::format("threshold_ratio: {} is outside [0, 1]", threshold_ratio);
  }
  if (outside(min_threshold, 0, 255)) {
    return fmt::format("min_threshold: {} is outside [0, 255]", min_threshold);
  }
  if (min_area_px < 1) return fmt::format("min_area_px: {} is below 1", min_area_px);
  if (max_area_px < min_area_px) {
    return fmt::format("max_area_px: {} is below min_area_px, {}", max_area_px, min_area_px);
  }
  if (outside(min_circularity, 0, 1)) {
    return fmt::format("min_circularity: {} is outside [0, 1]", min_circularity);
  }
  if (circularity_min_area_px < 0) {
    return fmt::format("circularity_min_area_px: {} is below 0", circularity_min_area_px);
  }
  if (region_of_interest.width < 0 || region_of_interest.height < 0) {
    return fmt::format("region_of_interest: {} x {} has a negative size", region_of_interest.width,
                       region_of_interest.height);
  }
  if (connectivity != 4 && connectivity != 8) {
    return fmt::format("connectivity: {}; 4 or 8", connectivity);
  }
  if (centroid_margin_px < 0) {
    return fmt::format("centroid_margin_px: {} is below 0", centroid_margin_px);
  }
  if (outside(centroid_level, 0, 1)) {
    return fmt::format("centroid_level: {} is outside [0, 1]", centroid_level);
  }
  if (!(pixel_noise >= 0)) return fmt::format("pixel_noise: {} is below 0", pixel_noise);
  if (!(sampling_error_px >= 0)) {
    return fmt::format("sampling_error_px: {} is below 0", sampling_error_px);
  }
  return std::nullopt;
}

FiducialDetector::FiducialDetector(FiducialDetectorOptions options) { set_options(options); }

void FiducialDetector::set_options(const FiducialDetectorOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("FiducialDetectorOptions::" + *problem);
  }
  options_ = options;
}

const std::vector<DetectedFiducial>& FiducialDetector::detect(const cv::Mat& mono8,
                                                              DetectionStats* stats) {
  if (!mono8.empty() && mono8.type() != CV_8UC1) {
    throw std::invalid_argument("detect_fiducials: expected a CV_8UC1 image, got " +
                                cv::typeToString(mono8.type()));
  }
  fiducials_.clear();
  DetectionStats local_stats;
  DetectionStats& s = stats != nullptr ? *stats : local_stats;
  s = DetectionStats{};

  const cv::Rect image_area(0, 0, mono8.cols, mono8.rows);
  const cv::Rect& requested = options_.region_of_interest;
  const cv::Rect area = requested.empty() ? image_area : (requested & image_area);
  if (mono8.empty() || area.empty()) return fiducials_;
  const cv::Mat roi = mono8(area);

  row_peaks_.resize(static_cast<size_t>(roi.rows));
  uint8_t peak = 0;
  for (int y = 0; y < roi.rows; ++y) {
    row_peaks_[y] = row_peak(roi.ptr<uint8_t>(y), roi.cols);
    peak = std::max(peak, row_peaks_[y]);
  }
  const double threshold = std::max(options_.min_threshold, options_.threshold_ratio * peak);
  s.peak = peak;
  s.threshold = threshold;
  // Pixels strictly brighter than the threshold, as cv::threshold(THRESH_BINARY) keeps them:
  // every used pixel then has a positive weight.
  const int level = static_cast<int>(std::floor(threshold)) + 1;
  if (level > 255) return fiducials_;

  find_runs(roi, level);
  collect_regions();
  mark_crowded_regions();
  s.regions = static_cast<int>(regions_.size());

  for (int index = 0; index < static_cast<int>(regions_.size()); ++index) {
    const Region& region = regions_[index];
    if (region.pixels < options_.min_area_px) {
      ++s.rejected_small;
      continue;
    }
    if (region.pixels > options_.max_area_px) {
      ++s.rejected_large;
      continue;
    }
    const bool touches_border = region.x_min == 0 || region.y_min == 0 ||
                                region.x_max == roi.cols - 1 || region.y_max == roi.rows - 1;
    if (touches_border && options_.reject_border_regions) {
      ++s.rejected_at_border;
      continue;
    }
    const double roundness = circularity(roi, region, threshold);
    if (region.pixels >= options_.circularity_min_area_px && roundness < options_.min_circularity) {
      ++s.rejected_not_round;
      continue;
    }
    Centroid centroid;
    double sampling_error = options_.sampling_error_px;
    if (!window_centroid(roi, index, threshold, centroid)) {
      centroid = region_centroid(region, threshold);
      sampling_error *= kThresholdOnlySampling;
    }
    DetectedFiducial& fiducial = fiducials_.emplace_back();
    fiducial.x = centroid.x + area.x;
    fiducial.y = centroid.y + area.y;
    fiducial.area_px = static_cast<double>(region.pixels);
    fiducial.circularity = roundness;
    fiducial.peak = region.peak;
    fiducial.uncertainty_px = std::sqrt(centroid.sigma * centroid.sigma +
                                        sampling_error * sampling_error / fiducial.area_px);
    fiducial.touches_border = touches_border;
  }
  s.accepted = static_cast<int>(fiducials_.size());
  return fiducials_;
}

// Weights Iᵢ - threshold over the region's own pixels, from the sums kept per run.
FiducialDetector::Centroid FiducialDetector::region_centroid(const Region& region,
                                                             double threshold) const {
  const auto n = static_cast<double>(region.pixels);
  const auto sum_x = static_cast<double>(region.sum_x);
  const auto sum_y = static_cast<double>(region.sum_y);
  // Every pixel of a region is brighter than the threshold, so the weight is positive.
  const double weight = static_cast<double>(region.sum_intensity) - threshold * n;
  Centroid centroid;
  centroid.x = (static_cast<double>(region.sum_intensity_x) - threshold * sum_x) / weight;
  centroid.y = (static_cast<double>(region.sum_intensity_y) - threshold * sum_y) / weight;
  centroid.sigma = centroid_sigma(options_.pixel_noise, weight, n, centroid.x, sum_x,
                                  static_cast<double>(region.sum_xx), centroid.y, sum_y,
                                  static_cast<double>(region.sum_yy));
  return centroid;
}

// Weights Iᵢ - level over a window around the region (see DetectedFiducial::x). False when
// the window is off (centroid_margin_px = 0) or has no dark surround to take a level from.
//
// A crowded region (mark_crowded_regions()) would share its window with another region, whose
// flank pulls the centroid towards it: falling back to the threshold-only centroid cost
// 0.12 px RMS on the volume demo's images, five times a lone blob's error. Its window is
// instead cut to a disc about the region's centre reaching halfway to the nearest
// neighbour's, which keeps the neighbour out and cuts the region's own flank alike on every
// side; the disc is centred on the threshold-only centroid first, then once more on the
// centroid that gives.
bool FiducialDetector::window_centroid(const cv::Mat& roi, int index, double threshold,
                                       Centroid& out) {
  const Region& region = regions_[index];
  const int margin = options_.centroid_margin_px;
  if (margin == 0) return false;
  Window window;
  window.left = std::max(0, region.x_min - margin);
  window.right = std::min(roi.cols - 1, region.x_max + margin);
  window.top = std::max(0, region.y_min - margin);
  window.bottom = std::min(roi.rows - 1, region.y_max + margin);
  if (window.right - window.left < 2 || window.bottom - window.top < 2) return false;
  if (!region.crowded) return weighted_centroid(roi, window, threshold, out);

  const Centroid own = region_centroid(region, threshold);
  double nearest = std::numeric_limits<double>::infinity();
  const auto neighbours =
      std::equal_range(crowding_.begin(), crowding_.end(), std::pair<int, int>(index, -1),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto it = neighbours.first; it != neighbours.second; ++it) {
    const Centroid other = region_centroid(regions_[it->second], threshold);
    nearest = std::min(nearest, std::hypot(other.x - own.x, other.y - own.y));
  }
  window.radius = nearest / 2;
  // Below this the disc would cut the blob itself, not its flank.
  constexpr double kLeastRadiusPx = 2;
  if (window.radius < kLeastRadiusPx) return false;
  window.centre_x = own.x;
  window.centre_y = own.y;
  if (!weighted_centroid(roi, window, threshold, out)) return false;
  window.centre_x = out.x;
  window.centre_y = out.y;
  return weighted_centroid(roi, window, threshold, out);
}

bool FiducialDetector::weighted_centroid(const cv::Mat& roi, const Window& window, double threshold,
                                         Centroid& out) {
  const int left = window.left, right = window.right, top = window.top, bottom = window.bottom;
  const bool disc = std::isfinite(window.radius);
  const double radius_squared = window.radius * window.radius;
  auto inside = [&](int x, int y) {
    const double dx = x - window.centre_x, dy = y - window.centre_y;
    return dx * dx + dy * dy <= radius_squared;
  };

  // The local background: the median of the rim (of the window, or of its disc), which lies
  // beyond the threshold's reach. The median ignores the few rim pixels a blob's flank may
  // reach.
  window_rim_.clear();
  if (!disc) {
    const uint8_t* top_row = roi.ptr<uint8_t>(top);
    const uint8_t* bottom_row = roi.ptr<uint8_t>(bottom);
    window_rim_.insert(window_rim_.end(), top_row + left, top_row + right + 1);
    window_rim_.insert(window_rim_.end(), bottom_row + left, bottom_row + right + 1);
    for (int y = top + 1; y < bottom; ++y) {
      window_rim_.push_back(roi.ptr<uint8_t>(y)[left]);
      window_rim_.push_back(roi.ptr<uint8_t>(y)[right]);
    }
  } else {
    // Pixels of the window within a pixel inside the disc's edge.
    const double inner = std::max(0.0, window.radius - 1);
    for (int y = top; y <= bottom; ++y) {
      const uint8_t* row = roi.ptr<uint8_t>(y);
      for (int x = left; x <= right; ++x) {
        const double dx = x - window.centre_x, dy = y - window.centre_y;
        const double squared = dx * dx + dy * dy;
        if (squared <= radius_squared && squared > inner * inner) window_rim_.push_back(row[x]);
      }
    }
    if (window_rim_.size() < 4) return false;
  }
  auto middle = window_rim_.begin() + static_cast<std::ptrdiff_t>(window_rim_.size() / 2);
  std::nth_element(window_rim_.begin(), middle, window_rim_.end());
  const double background = *middle;
  if (background >= threshold) return false;  // no dark surround: a blob among blobs
  const double level = background + options_.centroid_level * (threshold - background);

  // Integer sums over the pixels above the level (branch-free), weighted afterwards:
  // Σ (Iᵢ - level) xᵢ = Σ Iᵢxᵢ - level Σ xᵢ.
  const int first_used = static_cast<int>(std::floor(level)) + 1;
  int64_t n = 0, sum_i = 0, sum_ix = 0, sum_iy = 0, sum_x = 0, sum_xx = 0, sum_y = 0, sum_yy = 0;
  for (int y = top; y <= bottom; ++y) {
    const uint8_t* row = roi.ptr<uint8_t>(y);
    int64_t row_n = 0, row_i = 0, row_ix = 0, row_x = 0, row_xx = 0;
    for (int x = left; x <= right; ++x) {
      const int used = row[x] >= first_used && (!disc || inside(x, y)) ? 1 : 0;
      const int intensity = used * row[x];
      row_n += used;
      row_i += intensity;
      row_ix += static_cast<int64_t>(intensity) * x;
      row_x += used * x;
      row_xx += static_cast<int64_t>(used * x) * x;
    }
    n += row_n;
    sum_i += row_i;
    sum_ix += row_ix;
    sum_iy += row_i * y;
    sum_x += row_x;
    sum_xx += row_xx;
    sum_y += row_n * y;
    sum_yy += row_n * y * y;
  }
  const auto count = static_cast<double>(n);
  const double weight = static_cast<double>(sum_i) - level * count;
  if (weight <= 0) return false;
  out.x = (static_cast<double>(sum_ix) - level * static_cast<double>(sum_x)) / weight;
  out.y = (static_cast<double>(sum_iy) - level * static_cast<double>(sum_y)) / weight;
  out.sigma = centroid_sigma(options_.pixel_noise, weight, count, out.x, static_cast<double>(sum_x),
                             static_cast<double>(sum_xx), out.y, static_cast<double>(sum_y),
                             static_cast<double>(sum_yy));
  return true;
}

void FiducialDetector::find_runs(const cv::Mat& roi, int level) {
  runs_.clear();
  int previous_begin = 0, previous_end = 0;  // runs of the row above, if it had any
  int previous_row = -2;
  for (int y = 0; y < roi.rows; ++y) {
    if (row_peaks_[y] < level) continue;
    const uint8_t* row = roi.ptr<uint8_t>(y);
    const int current_begin = static_cast<int>(runs_.size());
    for (int x = next_bright_pixel(row, 0, roi.cols, level); x < roi.cols;
         x = next_bright_pixel(row, x, roi.cols, level)) {
      Run& run = runs_.emplace_back();
      run.y = y;
      run.x_begin = x;
      run.parent = static_cast<int>(runs_.size()) - 1;
      int64_t sum = 0, sum_x = 0;
      int peak = 0;
      for (; x < roi.cols && row[x] >= level; ++x) {
        sum += row[x];
        sum_x += static_cast<int64_t>(row[x]) * x;
        peak = std::max<int>(peak, row[x]);
      }
      run.x_end = x;
      run.sum_intensity = sum;
      run.sum_intensity_x = sum_x;
      run.peak = peak;
    }
    if (previous_row == y - 1) join_runs(previous_begin, previous_end, current_begin);
    previous_begin = current_begin;
    previous_end = static_cast<int>(runs_.size());
    previous_row = y;
  }
}

// Joins each run of the current row with the runs of the row above that it touches. Both
// rows' runs are sorted and disjoint, so one forward sweep finds every touching pair.
void FiducialDetector::join_runs(int previous_begin, int previous_end, int current_begin) {
  // With 8-connectivity a run also touches runs that end or start one pixel beside it.
  const int reach = options_.connectivity == 8 ? 1 : 0;
  int first_candidate = previous_begin;
  for (int current = current_begin; current < static_cast<int>(runs_.size()); ++current) {
    const Run& run = runs_[current];
    while (first_candidate < previous_end && runs_[first_candidate].x_end + reach <= run.x_begin) {
      ++first_candidate;
    }
    for (int above = first_candidate;
         above < previous_end && runs_[above].x_begin < run.x_end + reach; ++above) {
      int a = find_root(current), b = find_root(above);
      // The root is the region's first run in scan order: its topmost, leftmost pixel starts
      // the outline trace.
      if (a < b) {
        runs_[b].parent = a;
      } else if (b < a) {
        runs_[a].parent = b;
      }
    }
  }
}

int FiducialDetector::find_root(int run) {
  while (runs_[run].parent != run) {
    runs_[run].parent = runs_[runs_[run].parent].parent;  // path halving
    run = runs_[run].parent;
  }
  return run;
}

void FiducialDetector::collect_regions() {
  regions_.clear();
  for (int index = 0; index < static_cast<int>(runs_.size()); ++index) {
    const int root = find_root(index);
    Run& run = runs_[index];
    run.next_in_region = -1;
    Region* region;
    if (root == index) {
      run.region = static_cast<int>(regions_.size());
      region = &regions_.emplace_back();
      region->first_run = region->last_run = index;
      region->x_min = run.x_begin;
      region->x_max = run.x_end - 1;
      region->y_min = region->y_max = run.y;
    } else {
      // Roots come first in scan order, so the root's region exists already.
      region = &regions_[runs_[root].region];
      runs_[region->last_run].next_in_region = index;
      region->last_run = index;
      region->x_min = std::min(region->x_min, run.x_begin);
      region->x_max = std::max(region->x_max, run.x_end - 1);
      region->y_max = run.y;
    }
    const int64_t pixels = run.x_end - run.x_begin;
    const int64_t y = run.y;
    region->pixels += pixels;
    region->sum_intensity += run.sum_intensity;
    region->sum_intensity_x += run.sum_intensity_x;
    region->sum_intensity_y += y * run.sum_intensity;
    region->sum_x += (static_cast<int64_t>(run.x_begin) + run.x_end - 1) * pixels / 2;
    region->sum_xx += sum_of_squares(run.x_end - 1) - sum_of_squares(run.x_begin - 1);
    region->sum_y += y * pixels;
    region->sum_yy += y * y * pixels;
    region->peak = std::max(region->peak, run.peak);
  }
}

// Flags regions closer to another than twice the centroid margin: their centroid windows
// would overlap. Regions come in order of their top row, so for each region only those that
// start above its bottom (plus the reach) need a look.
void FiducialDetector::mark_crowded_regions() {
  crowding_.clear();
  const int reach = 2 * options_.centroid_margin_px;
  const int count = static_cast<int>(regions_.size());
  for (int i = 0; i < count; ++i) {
    Region& a = regions_[i];
    for (int j = i + 1; j < count && regions_[j].y_min <= a.y_max + reach; ++j) {
      Region& b = regions_[j];
      if (b.x_min <= a.x_max + reach && b.x_max + reach >= a.x_min) {
        a.crowded = b.crowded = true;
        crowding_.emplace_back(i, j);
        crowding_.emplace_back(j, i);
      }
    }
  }
  std::sort(crowding_.begin(), crowding_.end());
}

// Circularity 4πA/P² of the region's iso-line at the threshold: the outline where the
// image, interpolated linearly between pixel centres, crosses the threshold (marching
// squares on the region's patch). A and P of that sub-pixel outline are those of the blob's
// real shape at the threshold, nearly independent of its size and of where it falls on the
// pixel grid; the path through the rim pixels' centres (cv::findContours + cv::arcLength, the
// seed's measure) makes a small disc look octagonal or spiky (0.75-0.95 by position) and a
// line enclose nothing.
//
// Pixels of the region carry I - threshold (> 0); every other pixel min(I - threshold, 0), so
// that another region in the patch is not part of this outline; pixels beyond the image 0.
// Each cell between four pixel centres adds the segments where that value crosses zero,
// oriented with the region on their right, so that the enclosed area is the sum of the
// segments' shoelace terms (Green's theorem) without linking them into a chain. In a saddle
// cell, two diagonal region pixels are joined under 8-connectivity and parted under 4.
double FiducialDetector::circularity(const cv::Mat& roi, const Region& region, double threshold) {
  const int box_width = region.x_max - region.x_min + 1;
  const int box_height = region.y_max - region.y_min + 1;
  if (static_cast<int64_t>(box_width) * box_height > kLargestOutlinedBox) {
    // A sparse region with a large bounding box: its outline runs across the longer side and
    // back, so P >= 2 (L - 1), and it stays within the cells next to the region's pixels, so
    // A <= 4 x pixels. When that bound fails already it is the answer, and a huge patch is
    // spared.
    const double span = 2.0 * (std::max(box_width, box_height) - 1);
    const double bound =
        4 * std::numbers::pi * 4 * static_cast<double>(region.pixels) / (span * span);
    if (bound < options_.min_circularity) return bound;
  }

  // The patch: the bounding box and a margin of one pixel, where the outline closes.
  fill_outline_patch(roi, region, threshold);
  const auto [length, twice_area] = outline_of_patch(patch_values_.data(), box_width + 2,
                                                     box_height + 2, options_.connectivity == 8);
  if (length <= 0) return 0;
  return 4 * std::numbers::pi * (std::abs(twice_area) / 2) / (length * length);
}

void FiducialDetector::fill_outline_patch(const cv::Mat& roi, const Region& region,
                                          double threshold) {
  const int stride = region.x_max - region.x_min + 3;
  const int patch_height = region.y_max - region.y_min + 3;
  const int left = region.x_min - 1, top = region.y_min - 1;
  patch_mask_.assign(static_cast<size_t>(stride) * patch_height, 0);
  for (int index = region.first_run; index >= 0; index = runs_[index].next_in_region) {
    const Run& run = runs_[index];
    uint8_t* row = patch_mask_.data() + static_cast<size_t>(run.y - top) * stride;
    std::fill(row + (run.x_begin - left), row + (run.x_end - left), 1);
  }
  patch_values_.resize(patch_mask_.size());
  for (int py = 0; py < patch_height; ++py) {
    const int y = top + py;
    float* values = patch_values_.data() + static_cast<size_t>(py) * stride;
    const uint8_t* mask = patch_mask_.data() + static_cast<size_t>(py) * stride;
    const uint8_t* pixels = y >= 0 && y < roi.rows ? roi.ptr<uint8_t>(y) : nullptr;
    for (int px = 0; px < stride; ++px) {
      const int x = left + px;
      if (pixels == nullptr || x < 0 || x >= roi.cols) {
        values[px] = 0;
        continue;
      }
      const auto above = static_cast<float>(pixels[x] - threshold);
      values[px] = mask[px] != 0 ? above : std::min(above, 0.0f);
    }
  }
}

std::vector<DetectedFiducial> detect_fiducials(const cv::Mat& mono8,
                                               const FiducialDetectorOptions& options,
                                               DetectionStats* stats) {
  FiducialDetector detector(options);
  return detector.detect(mono8, stats);
}

}  // namespace mocap::tracking
