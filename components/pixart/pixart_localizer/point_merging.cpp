#include "pixart/pixart_localizer/point_merging.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap::pixart::localization {
namespace {

struct ViewPoint {
  size_t camera;
  int64_t stamp_ns;
  Eigen::Vector2d position;
};

struct CandidatePair {
  double distance;
  size_t a, b;  // indices into the ViewPoints
};

int64_t to_ns(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e9)); }

// Why `value` cannot be a distance or a time that must be positive: not above 0, or infinite.
std::optional<std::string> not_positive(const char* name, double value) {
  if (!(value > 0)) return fmt::format("{}: {} is not above 0", name, value);
  if (!std::isfinite(value)) return fmt::format("{}: {} is not finite", name, value);
  return std::nullopt;
}

}  // namespace

std::optional<std::string> MergeOptions::problem() const {
  if (auto problem = not_positive("merge_distance_m", merge_distance_m)) return problem;
  if (!(merge_window_s >= 0)) return fmt::format("merge_window_s: {} is below 0", merge_window_s);
  if (auto problem = not_positive("stale_after_s", stale_after_s)) return problem;
  return std::nullopt;
}

MergedPoints merge_views(const std::vector<CameraView>& views, const MergeOptions& options) {
  if (auto problem = options.problem()) throw std::invalid_argument("MergeOptions::" + *problem);
  MergedPoints merged;
  bool any = false;
  for (const CameraView& view : views) {
    if (view.received && (!any || view.stamp_ns > merged.stamp_ns)) {
      merged.stamp_ns = view.stamp_ns;
      any = true;
    }
  }
  if (!any) return merged;

  const int64_t oldest_fresh_ns = merged.stamp_ns - to_ns(options.stale_after_s);
  const int64_t window_ns = to_ns(options.merge_window_s);
  std::vector<ViewPoint> points;
  for (size_t camera = 0; camera < std::min(views.size(), kMaxCameras); ++camera) {
    const CameraView& view = views[camera];
    if (!view.received || view.stamp_ns < oldest_fresh_ns) continue;
    ++merged.cameras;
    for (const Eigen::Vector2d& p : view.points) points.push_back({camera, view.stamp_ns, p});
  }

  auto mergeable = [&](const ViewPoint& a, const ViewPoint& b) {
    return a.camera != b.camera && std::llabs(a.stamp_ns - b.stamp_ns) <= window_ns &&
           (a.position - b.position).norm() <= options.merge_distance_m;
  };
  std::vector<CandidatePair> pairs;
  for (size_t a = 0; a < points.size(); ++a) {
    for (size_t b = a + 1; b < points.size(); ++b) {
      if (mergeable(points[a], points[b])) {
        pairs.push_back({(points[a].position - points[b].position).norm(), a, b});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const CandidatePair& l, const CandidatePair& r) { return l.distance < r.distance; });

  // group_of[i]: the group point i belongs to; members[g]: the points of group g.
  std::vector<size_t> group_of(points.size());
  std::iota(group_of.begin(), group_of.end(), 0);
  std::vector<std::vector<size_t>> members(points.size());
  for (size_t i = 0; i < points.size(); ++i) members[i] = {i};
  for (const CandidatePair& pair : pairs) {
    size_t ga = group_of[pair.a], gb = group_of[pair.b];
    if (ga == gb) continue;
    bool joinable = true;
    for (size_t i : members[ga]) {
      for (size_t j : members[gb]) joinable = joinable && mergeable(points[i], points[j]);
    }
    if (!joinable) continue;
    for (size_t j : members[gb]) group_of[j] = ga;
    members[ga].insert(members[ga].end(), members[gb].begin(), members[gb].end());
    members[gb].clear();
  }

  for (const std::vector<size_t>& group : members) {
    if (group.empty()) continue;
    MergedPoint point;
    for (size_t i : group) {
      point.position += points[i].position;
      point.cameras |= CameraSet{1} << points[i].camera;
    }
    point.position /= static_cast<double>(group.size());
    point.views = static_cast<int>(group.size());
    merged.points.push_back(point);
  }
  return merged;
}

}  // namespace mocap::pixart::localization
