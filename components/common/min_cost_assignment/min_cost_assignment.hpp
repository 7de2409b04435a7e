// The assignment of rows to columns at the least total cost (the Hungarian method, by
// shortest augmenting paths, O(rows² · columns)), over a whole cost matrix or over the pairs a
// gate allows: the tracker's predicted markers and its detections, the swarm's robots and the
// marker cloud.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mocap {

// Per row, the column it gets; every row gets a different column. Needs rows <= columns and
// finite costs: a pair that must not be chosen gets a cost above any sum of allowed ones.
std::vector<int> min_cost_assignment(const Eigen::MatrixXd& cost);

// A pair a gate allows, at its cost.
struct AllowedPair {
  int row = 0;
  int column = 0;
  double cost = 0;
};

// Per row, the column it gets or -1: the least total cost over the allowed pairs, a row left
// without a column costing `unassigned_cost[row]`. Rows and columns linked by no chain of
// allowed pairs are independent: each group is solved on its own, so that a hundred robots
// whose gates touch one or two neighbours' cost a hundred small problems, not one large one.
// `unassigned_cost` has one entry per row; every cost is finite.
std::vector<int> min_cost_assignment(int rows, int columns, const std::vector<AllowedPair>& allowed,
                                     const std::vector<double>& unassigned_cost);

}  // namespace mocap
