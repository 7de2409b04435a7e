// The assignment of rows to columns at the least total cost (the Hungarian method, by
// shortest augmenting paths, O(rows² · columns)).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace mocap::tracking {

// Per row, the column it gets; every row gets a different column. Needs rows <= columns and
// finite costs: a pair that must not be chosen gets a cost above any sum of allowed ones.
std::vector<int> min_cost_assignment(const Eigen::MatrixXd& cost);

}  // namespace mocap::tracking
