// PartTranslations (part_translations.hpp): the parts by a depth-first search over the nonzero
// blocks, each part's translation block, and the correction.
#include "core/solve/part_translations.hpp"

#include "core/system/block_sparse_matrix.hpp"

#include <Eigen/LU>

namespace tissue {

void PartTranslations::setup(const ShiftedSystem& a) {
  const BlockSparseMatrix& k = *a.stiffness;
  const int n = k.block_rows();
  m_part_of_row.assign(static_cast<size_t>(n), -1);
  m_inverse.clear();
  std::vector<Eigen::Matrix3d>& block_sum = m_inverse;  // Z^T A Z, inverted in place below
  for (int root = 0; root < n; ++root) {
    if (m_part_of_row[static_cast<size_t>(root)] >= 0) continue;
    const int part = static_cast<int>(block_sum.size());
    block_sum.push_back(Eigen::Matrix3d::Zero());
    Eigen::Matrix3d& sum = block_sum.back();
    m_part_of_row[static_cast<size_t>(root)] = part;
    m_stack.assign(1, root);
    while (!m_stack.empty()) {
      const int row = m_stack.back();
      m_stack.pop_back();
      sum.diagonal() += a.diagonal->segment<3>(3L * row);
      for (int slot = k.row_begin(row); slot < k.row_begin(row) + k.row_size(row); ++slot) {
        const auto block = k.block(slot);
        if (block.isZero(0.0)) continue;  // a block kept in the pattern with nothing in it joins nothing
        sum += a.stiffness_scale * block;
        const int column = k.slot_column(slot);
        if (m_part_of_row[static_cast<size_t>(column)] < 0) {
          m_part_of_row[static_cast<size_t>(column)] = part;
          m_stack.push_back(column);
        }
      }
    }
  }
  for (Eigen::Matrix3d& sum : block_sum) {
    // Positive definite for a positive d; a part without (a row nothing weighs) is left as it is.
    const Eigen::Matrix3d inverse = sum.determinant() > 0.0 ? sum.inverse().eval() : Eigen::Matrix3d::Zero();
    sum = inverse.allFinite() ? inverse : Eigen::Matrix3d::Zero();
  }
  m_sums.resize(m_inverse.size());
}

void PartTranslations::correct(const Eigen::VectorXd& residual, Eigen::VectorXd& x) {
  std::fill(m_sums.begin(), m_sums.end(), Eigen::Vector3d::Zero());
  const auto n = static_cast<Eigen::Index>(m_part_of_row.size());
  for (Eigen::Index row = 0; row < n; ++row) {
    m_sums[static_cast<size_t>(m_part_of_row[static_cast<size_t>(row)])] += residual.segment<3>(3 * row);
  }
  for (size_t part = 0; part < m_sums.size(); ++part) m_sums[part] = m_inverse[part] * m_sums[part];
  for (Eigen::Index row = 0; row < n; ++row) {
    x.segment<3>(3 * row) += m_sums[static_cast<size_t>(m_part_of_row[static_cast<size_t>(row)])];
  }
}

}  // namespace tissue
