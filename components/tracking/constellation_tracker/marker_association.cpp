#include "tracking/constellation_tracker/marker_association.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/LU>

#include "common/min_cost_assignment/min_cost_assignment.hpp"

namespace mocap::tracking {
namespace {

struct Pair {
  int prediction;
  int fiducial;
  double cost;
};

int root_of(std::vector<int>& parent, int node) {
  while (parent[node] != node) {
    parent[node] = parent[parent[node]];
    node = parent[node];
  }
  return node;
}

}  // namespace

// Kept whole (about 85 lines): gating, the tangles and their assignments are three passes
// over the same pair list, in the order the comments give.
std::vector<int> associate_markers(const std::vector<PredictedMarker>& predictions,
                                   const std::vector<Eigen::Vector2d>& fiducials, double gate) {
  const int prediction_count = static_cast<int>(predictions.size());
  std::vector<int> result(predictions.size(), -1);
  // Fiducials sorted by x: a prediction looks only at those within its gate's reach.
  std::vector<int> by_x(fiducials.size());
  std::iota(by_x.begin(), by_x.end(), 0);
  by_x.erase(
      std::remove_if(by_x.begin(), by_x.end(), [&](int i) { return !fiducials[i].allFinite(); }),
      by_x.end());
  std::sort(by_x.begin(), by_x.end(),
            [&](int a, int b) { return fiducials[a].x() < fiducials[b].x(); });
  std::vector<Pair> pairs;
  for (int p = 0; p < prediction_count; ++p) {
    const PredictedMarker& predicted = predictions[p];
    if (!predicted.pixel.allFinite()) continue;
    const Eigen::Matrix2d information = predicted.covariance.inverse();
    if (!information.allFinite()) continue;
    const double reach_x = std::sqrt(gate * predicted.covariance(0, 0));
    const double reach_y = std::sqrt(gate * predicted.covariance(1, 1));
    auto first = std::lower_bound(by_x.begin(), by_x.end(), predicted.pixel.x() - reach_x,
                                  [&](int i, double x) { return fiducials[i].x() < x; });
    for (auto it = first; it != by_x.end(); ++it) {
      const Eigen::Vector2d offset = fiducials[*it] - predicted.pixel;
      if (offset.x() > reach_x) break;
      if (std::abs(offset.y()) > reach_y) continue;
      const double cost = offset.dot(information * offset);
      if (cost <= gate) pairs.push_back({p, *it, cost});
    }
  }
  if (pairs.empty()) return result;

  // Tangles: predictions and fiducials joined by pairs (fiducial f is node prediction_count + f).
  std::vector<int> parent(predictions.size() + fiducials.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const Pair& pair : pairs) {
    parent[root_of(parent, pair.prediction)] = root_of(parent, prediction_count + pair.fiducial);
  }
  std::vector<int> tangle_of_pair(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) {
    tangle_of_pair[k] = root_of(parent, pairs[k].prediction);
  }
  std::vector<size_t> order(pairs.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return tangle_of_pair[a] < tangle_of_pair[b]; });

  std::vector<int> rows, columns;
  for (size_t begin = 0; begin < order.size();) {
    size_t end = begin;
    while (end < order.size() && tangle_of_pair[order[end]] == tangle_of_pair[order[begin]]) ++end;
    if (end - begin == 1) {  // the common case: one prediction, one fiducial
      const Pair& only = pairs[order[begin]];
      result[only.prediction] = only.fiducial;
      begin = end;
      continue;
    }
    rows.clear();
    columns.clear();
    for (size_t k = begin; k < end; ++k) {
      rows.push_back(pairs[order[k]].prediction);
      columns.push_back(pairs[order[k]].fiducial);
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    // Columns: the tangle's fiducials, then one "no fiducial" column per prediction.
    const int n = static_cast<int>(rows.size()), m = static_cast<int>(columns.size());
    const double forbidden = gate * (n + 1) * 10;
    Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(n, m + n, forbidden);
    for (int r = 0; r < n; ++r) cost(r, m + r) = gate;
    for (size_t k = begin; k < end; ++k) {
      const Pair& pair = pairs[order[k]];
      const int r = static_cast<int>(std::lower_bound(rows.begin(), rows.end(), pair.prediction) -
                                     rows.begin());
      const int c = static_cast<int>(
          std::lower_bound(columns.begin(), columns.end(), pair.fiducial) - columns.begin());
      cost(r, c) = pair.cost;
    }
    const std::vector<int> assignment = min_cost_assignment(cost);
    for (int r = 0; r < n; ++r) {
      if (assignment[r] < m) result[rows[r]] = columns[assignment[r]];
    }
    begin = end;
  }
  return result;
}

}  // namespace mocap::tracking
