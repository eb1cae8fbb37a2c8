// Which block rows left the dynamics (DynamicsModel::rows_left): the one reading of that list, for
// the model that keeps it, the energy guard and the linear solvers alike.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tissue {

/// Whether block row `row` left the dynamics by `rows_left`: per row, nonzero where it left. The list
/// may be shorter than the rows (the rest are in); nullptr: every row is in.
[[nodiscard]] inline bool row_left(const std::vector<std::uint8_t>* rows_left, Eigen::Index row) {
  return rows_left != nullptr && row >= 0 && static_cast<std::size_t>(row) < rows_left->size() &&
         (*rows_left)[static_cast<std::size_t>(row)] != 0;
}

}  // namespace tissue
