// The Galerkin projection onto earlier solutions (galerkin_start.hpp).
#include "core/integrate/galerkin_start.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace tissue {

void galerkin_start(const ShiftedSystem& system, const Eigen::VectorXd& b,
                    const Eigen::Ref<const Eigen::MatrixXd>& columns, Eigen::VectorXd& x0, GalerkinStartWork& work,
                    const LinearSolver* solver) {
  x0.setZero(b.size());
  const Eigen::Index count = columns.cols();
  if (count == 0 || count > GALERKIN_MAX_COLUMNS || columns.rows() != b.size() || !columns.allFinite()) return;
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, GALERKIN_MAX_COLUMNS, GALERKIN_MAX_COLUMNS>;
  using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, GALERKIN_MAX_COLUMNS, 1>;
  if (solver == nullptr || !solver->multiply_set_up(system, columns, work.products)) {
    work.products.resize(b.size(), count);
    for (Eigen::Index k = 0; k < count; ++k) {
      work.column = columns.col(k);
      system.multiply(work.column, work.product);
      work.products.col(k) = work.product;
    }
  }
  const Small gram = columns.transpose() * work.products;
  const SmallVector projected_b = columns.transpose() * b;
  const Eigen::SelfAdjointEigenSolver<Small> eigen(Small(0.5 * (gram + gram.transpose())));
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  if (!(largest > 0.0) || !std::isfinite(largest)) return;
  SmallVector coefficients = SmallVector::Zero(count);
  for (Eigen::Index k = 0; k < count; ++k) {
    const double value = eigen.eigenvalues()[k];
    if (value > 1e-12 * largest) {
      coefficients += (eigen.eigenvectors().col(k).dot(projected_b) / value) * eigen.eigenvectors().col(k);
    }
  }
  x0.noalias() = columns * coefficients;
  if (!x0.allFinite()) x0.setZero();
}

}  // namespace tissue
