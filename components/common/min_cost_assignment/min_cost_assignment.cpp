#include "common/min_cost_assignment/min_cost_assignment.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace mocap {

std::vector<int> min_cost_assignment(const Eigen::MatrixXd& cost) {
  const int rows = static_cast<int>(cost.rows());
  const int columns = static_cast<int>(cost.cols());
  if (rows > columns) throw std::invalid_argument("min_cost_assignment: more rows than columns");
  const double infinity = std::numeric_limits<double>::infinity();
  // Potentials u (rows) and v (columns) keep every reduced cost cost - u - v non-negative;
  // column 0 is a virtual start, owner[j] the row (1-based) that holds column j.
  std::vector<double> u(rows + 1, 0), v(columns + 1, 0);
  std::vector<int> owner(columns + 1, 0), previous(columns + 1, 0);
  std::vector<double> slack(columns + 1);
  std::vector<char> visited(columns + 1);
  for (int row = 1; row <= rows; ++row) {
    owner[0] = row;
    int column = 0;
    std::fill(slack.begin(), slack.end(), infinity);
    std::fill(visited.begin(), visited.end(), 0);
    do {
      visited[column] = 1;
      const int from = owner[column];
      double delta = infinity;
      int next = 0;
      for (int j = 1; j <= columns; ++j) {
        if (visited[j]) continue;
        const double reduced = cost(from - 1, j - 1) - u[from] - v[j];
        if (reduced < slack[j]) {
          slack[j] = reduced;
          previous[j] = column;
        }
        if (slack[j] < delta) {
          delta = slack[j];
          next = j;
        }
      }
      for (int j = 0; j <= columns; ++j) {
        if (visited[j]) {
          u[owner[j]] += delta;
          v[j] -= delta;
        } else {
          slack[j] -= delta;
        }
      }
      column = next;
    } while (owner[column] != 0);
    // Flip the augmenting path back to the start.
    do {
      const int before = previous[column];
      owner[column] = owner[before];
      column = before;
    } while (column != 0);
  }
  std::vector<int> assignment(rows, -1);
  for (int j = 1; j <= columns; ++j) {
    if (owner[j] != 0) assignment[owner[j] - 1] = j - 1;
  }
  return assignment;
}

namespace {

int root_of(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

}  // namespace

std::vector<int> min_cost_assignment(int rows, int columns, const std::vector<AllowedPair>& allowed,
                                     const std::vector<double>& unassigned_cost) {
  if (rows < 0 || columns < 0 || unassigned_cost.size() != static_cast<size_t>(rows)) {
    throw std::invalid_argument("min_cost_assignment: one unassigned cost per row");
  }
  // Groups: rows are 0..rows-1, columns rows..rows+columns-1.
  std::vector<int> parent(static_cast<size_t>(rows + columns));
  std::iota(parent.begin(), parent.end(), 0);
  for (const AllowedPair& pair : allowed) {
    if (pair.row < 0 || pair.row >= rows || pair.column < 0 || pair.column >= columns) {
      throw std::invalid_argument("min_cost_assignment: a pair outside the rows or columns");
    }
    parent[root_of(parent, pair.row)] = root_of(parent, rows + pair.column);
  }
  std::vector<std::vector<int>> group_pairs(parent.size());
  for (size_t p = 0; p < allowed.size(); ++p) {
    group_pairs[root_of(parent, allowed[p].row)].push_back(static_cast<int>(p));
  }
  std::vector<int> assignment(static_cast<size_t>(rows), -1);
  std::vector<int> local_row(static_cast<size_t>(rows), -1),
      local_column(static_cast<size_t>(columns), -1);
  for (const std::vector<int>& pairs : group_pairs) {
    if (pairs.empty()) continue;
    std::vector<int> group_rows, group_columns;
    for (int p : pairs) {
      const AllowedPair& pair = allowed[p];
      if (local_row[pair.row] < 0) {
        local_row[pair.row] = static_cast<int>(group_rows.size());
        group_rows.push_back(pair.row);
      }
      if (local_column[pair.column] < 0) {
        local_column[pair.column] = static_cast<int>(group_columns.size());
        group_columns.push_back(pair.column);
      }
    }
    if (pairs.size() == 1) {
      const AllowedPair& pair = allowed[pairs[0]];
      if (pair.cost < unassigned_cost[pair.row]) assignment[pair.row] = pair.column;
      continue;
    }
    // Each row has a column of its own that stands for "none", at its unassigned cost; a pair
    // not allowed costs more than any choice of allowed ones.
    const int n = static_cast<int>(group_rows.size());
    const int m = static_cast<int>(group_columns.size());
    double forbidden = 1;
    for (int p : pairs) forbidden += std::abs(allowed[p].cost);
    for (int row : group_rows) forbidden += std::abs(unassigned_cost[row]);
    forbidden *= 2;
    Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(n, m + n, forbidden);
    for (int p : pairs) {
      const AllowedPair& pair = allowed[p];
      double& entry = cost(local_row[pair.row], local_column[pair.column]);
      entry = std::min(entry, pair.cost);
    }
    for (int r = 0; r < n; ++r) cost(r, m + r) = unassigned_cost[group_rows[r]];
    const std::vector<int> chosen = min_cost_assignment(cost);
    for (int r = 0; r < n; ++r) {
      if (chosen[r] < m) assignment[group_rows[r]] = group_columns[chosen[r]];
    }
    for (int row : group_rows) local_row[row] = -1;
    for (int column : group_columns) local_column[column] = -1;
  }
  return assignment;
}

}  // namespace mocap
