#include "tracking/constellation_tracker/min_cost_assignment.hpp"

#include <limits>
#include <stdexcept>

namespace mocap::tracking {

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

}  // namespace mocap::tracking
