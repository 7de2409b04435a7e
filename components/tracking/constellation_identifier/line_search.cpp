#include "tracking/constellation_identifier/line_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <fmt/format.h>

namespace mocap::constellations {

namespace {

// The points in order along one image axis, coordinates side by side for a vectorised loop.
struct AxisOrder {
  std::vector<int> index;  // point indices by increasing coordinate
  std::vector<int> rank;   // per point, its place in `index`
  std::vector<float> x, y;

  AxisOrder(const std::vector<Eigen::Vector2d>& points, int axis)
      : index(points.size()), rank(points.size()), x(points.size()), y(points.size()) {
    for (size_t i = 0; i < points.size(); ++i) index[i] = static_cast<int>(i);
    std::stable_sort(index.begin(), index.end(),
                     [&](int a, int b) { return points[a][axis] < points[b][axis]; });
    for (size_t r = 0; r < index.size(); ++r) {
      rank[index[r]] = static_cast<int>(r);
      x[r] = static_cast<float>(points[index[r]].x());
      y[r] = static_cast<float>(points[index[r]].y());
    }
  }
};

// How many of the points order.x/y[first..last] lie within `tolerance` (scaled by the length,
// as `cross` is) of the segment from `from` along `d` (|d|² = length2), ends included, widened
// by a hundredth. Four at a time where SSE2 is there (every x86-64).
int count_near_segment(const AxisOrder& order, int first, int last, const Eigen::Vector2d& from,
                       const Eigen::Vector2d& d, double tolerance, double length2) {
  const float fx = static_cast<float>(from.x()), fy = static_cast<float>(from.y());
  const float dx = static_cast<float>(d.x()), dy = static_cast<float>(d.y());
  const float reach = static_cast<float>(tolerance) * 1.01f;
  const float slack = 0.01f * static_cast<float>(length2);
  const float low = -slack, high = static_cast<float>(length2) + slack;
  const float* xs = order.x.data();
  const float* ys = order.y.data();
  int count = 0;
  int r = first;
#ifdef __SSE2__
  const __m128 vfx = _mm_set1_ps(fx), vfy = _mm_set1_ps(fy), vdx = _mm_set1_ps(dx),
               vdy = _mm_set1_ps(dy), vreach = _mm_set1_ps(reach), vlow = _mm_set1_ps(low),
               vhigh = _mm_set1_ps(high), sign = _mm_set1_ps(-0.0f);
  for (; r + 3 <= last; r += 4) {
    const __m128 rx = _mm_sub_ps(_mm_loadu_ps(xs + r), vfx);
    const __m128 ry = _mm_sub_ps(_mm_loadu_ps(ys + r), vfy);
    const __m128 cross = _mm_andnot_ps(sign, _mm_sub_ps(_mm_mul_ps(vdx, ry), _mm_mul_ps(vdy, rx)));
    const __m128 u = _mm_add_ps(_mm_mul_ps(vdx, rx), _mm_mul_ps(vdy, ry));
    const __m128 near = _mm_and_ps(_mm_cmple_ps(cross, vreach),
                                   _mm_and_ps(_mm_cmpgt_ps(u, vlow), _mm_cmplt_ps(u, vhigh)));
    static constexpr int kBits[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
    count += kBits[_mm_movemask_ps(near)];
  }
#endif
  for (; r <= last; ++r) {
    const float rx = xs[r] - fx, ry = ys[r] - fy;
    const float cross = std::abs(dx * ry - dy * rx);
    const float u = dx * rx + dy * ry;
    count += cross <= reach && u > low && u < high;
  }
  return count;
}

}  // namespace

std::optional<std::string> LineSearchOptions::problem() const {
  if (!(tolerance_px > 0)) return fmt::format("tolerance_px: {} is not above 0", tolerance_px);
  if (min_points < 2) {
    return fmt::format("min_points: {}; a line takes two points at least", min_points);
  }
  // Compared squared: a negative length would pass for its opposite.
  if (!(min_length_px >= 0)) return fmt::format("min_length_px: {} is below 0", min_length_px);
  return std::nullopt;
}

std::vector<CollinearGroup> find_collinear_groups(const std::vector<Eigen::Vector2d>& points,
                                                  const LineSearchOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("LineSearchOptions::" + *problem);
  }
  std::vector<CollinearGroup> groups;
  const int n = static_cast<int>(points.size());
  if (n < options.min_points) return groups;
  // A point strictly between i and j and within the tolerance of their line lies inside their
  // bounding box grown by the tolerance, so along the axis where the box is narrower it is
  // among a few neighbours in that axis's order. Counting those first leaves the full test,
  // which also looks beyond the ends, to the few pairs with enough points between them.
  const AxisOrder by_axis[2] = {AxisOrder(points, 0), AxisOrder(points, 1)};
  const double tolerance_px = options.tolerance_px;
  const int needed_between = std::max(0, options.min_points - 2);
  const double min_length2 = options.min_length_px * options.min_length_px;
  std::vector<std::pair<double, int>> inliers;
  inliers.reserve(n);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      Eigen::Vector2d d = points[j] - points[i];
      double length2 = d.squaredNorm();
      if (!(length2 >= min_length2)) continue;
      int first = 0, last = n - 1;
      const AxisOrder* order = nullptr;
      if (needed_between > 0) {
        const int axis = std::abs(d.x()) <= std::abs(d.y()) ? 0 : 1;
        order = &by_axis[axis];
        const float* along = axis == 0 ? order->x.data() : order->y.data();
        first = std::min(order->rank[i], order->rank[j]);
        last = std::max(order->rank[i], order->rank[j]);
        const double low = along[first] - tolerance_px - 0.01;
        const double high = along[last] + tolerance_px + 0.01;
        while (first > 0 && along[first - 1] >= low) --first;
        while (last + 1 < n && along[last + 1] <= high) ++last;
        if (last - first + 1 < options.min_points) continue;  // too few in the slab at all
      }
      // With u along the line (0 at i, 1 at j) and the signed distance scaled by the length,
      // each point costs two dot products and no square root.
      double length = std::sqrt(length2);
      double tolerance = tolerance_px * length;
      if (order != nullptr) {
        // In single precision, with the bounds widened by a hundredth so that rounding can
        // only let more pairs through to the exact test below, never fewer; i and j are
        // counted too.
        const int between =
            count_near_segment(*order, first, last, points[i], d, tolerance, length2) - 2;
        if (between < needed_between) continue;
      }
      inliers.clear();
      inliers.emplace_back(0.0, i);
      inliers.emplace_back(1.0, j);
      double largest_offset = 0;
      bool spans = true;
      for (int k = 0; k < n && spans; ++k) {
        if (k == i || k == j) continue;
        Eigen::Vector2d r = points[k] - points[i];
        double cross = d.x() * r.y() - d.y() * r.x();
        if (std::abs(cross) > tolerance) continue;
        double u = d.dot(r) / length2;
        if (u <= 0.0 || u >= 1.0) {
          spans = false;  // a longer group contains this one; its own end pair reports it
        } else {
          inliers.emplace_back(u, k);
          largest_offset = std::max(largest_offset, std::abs(cross) / length);
        }
      }
      if (!spans || static_cast<int>(inliers.size()) < options.min_points) continue;
      std::sort(inliers.begin(), inliers.end());
      CollinearGroup group;
      group.largest_offset_px = largest_offset;
      for (const auto& [u, index] : inliers) group.points.push_back(index);
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

}  // namespace mocap::constellations
