// Minimum-cost assignment (Hungarian method) for a rectangular cost matrix.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace viper {

/// Solves min sum cost(r, assignment[r]) over assignments of rows to distinct columns, for
/// rows <= cols (throws std::invalid_argument otherwise). Returns, per row, its column. O(r^2 c).
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

}  // namespace viper
