// ShiftedSystem: the product with A = s K + diag(d), shared by the iterative solver and by the
// residual check of the direct one.
#include "core/solve/linear_solver.hpp"

#include <string>

namespace tissue {
namespace {

// y = s y + d x on the block rows [first_block_row, end_block_row), y holding K x there.
// Coefficient-wise and in place: Eigen evaluates this without a temporary.
void shift_rows(const ShiftedSystem& a, const Eigen::VectorXd& x, Eigen::VectorXd& y, int first_block_row,
                int end_block_row) {
  const long first = 3L * first_block_row;
  const long count = 3L * (end_block_row - first_block_row);
  y.segment(first, count).array() = a.stiffness_scale * y.segment(first, count).array() +
                                    a.diagonal->segment(first, count).array() * x.segment(first, count).array();
}

}  // namespace

void ShiftedSystem::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  stiffness->multiply(x, y);  // checks x and sizes y
  shift_rows(*this, x, y, 0, stiffness->block_rows());
}

void ShiftedSystem::multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first_block_row,
                                  int end_block_row) const {
  stiffness->multiply_rows(x, y, first_block_row, end_block_row);
  shift_rows(*this, x, y, first_block_row, end_block_row);
}

namespace {

std::string length_mismatch(std::string_view who, const char* what, long size, long rows) {
  return std::string(who) + ": " + what + " has length " + std::to_string(size) + ", the system has " +
         std::to_string(rows) + " rows";
}

}  // namespace

void ShiftedSystem::check(std::string_view who) const {
  if (stiffness == nullptr || diagonal == nullptr) {
    throw SolverError(std::string(who) + ": the system has no stiffness or no diagonal");
  }
  if (diagonal->size() != rows()) throw SolverError(length_mismatch(who, "the diagonal d", diagonal->size(), rows()));
}

void ShiftedSystem::check_sizes(const Eigen::VectorXd& b, const Eigen::VectorXd& x) const {
  constexpr std::string_view who = "linear solve";
  check(who);
  const long n = rows();
  const auto describe = [n, who](const char* what, long size) { return length_mismatch(who, what, size, n); };
  if (b.size() != n) throw SolverError(describe("the right-hand side b", b.size()));
  if (x.size() != n) throw SolverError(describe("the initial guess x", x.size()));
}

}  // namespace tissue
