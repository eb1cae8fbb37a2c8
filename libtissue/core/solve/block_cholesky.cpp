// BlockCholesky (see block_cholesky.hpp).
#include "core/solve/block_cholesky.hpp"

#include <Eigen/Cholesky>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cassert>

namespace tissue {

void BlockCholesky::analyze(const std::vector<int>& row_begin, const std::vector<int>& row_column,
                            const std::vector<int>& column_begin) {
  assert(column_begin.size() == row_begin.size() && !row_begin.empty());
  order_blocks(row_begin, row_column, column_begin);
  find_factor_pattern(row_begin, row_column);
  map_entries(row_begin, row_column);
  m_slot_of_row.assign(m_order.size(), -1);
  m_work.resize(static_cast<Eigen::Index>(BLOCK * m_order.size()));
}

void BlockCholesky::order_blocks(const std::vector<int>& row_begin, const std::vector<int>& row_column,
                                 const std::vector<int>& column_begin) {
  const int n = std::max(0, static_cast<int>(column_begin.size()) - 1);
  // The blocks' graph, both triangles, for the ordering.
  std::vector<Eigen::Triplet<double>> links;
  for (int a = 0; a < n; ++a) {
    links.emplace_back(a, a, 1.0);
    for (int e = row_begin[static_cast<size_t>(a)]; e < row_begin[static_cast<size_t>(a) + 1]; ++e) {
      const int b = row_column[static_cast<size_t>(e)];
      if (b <= a) continue;
      links.emplace_back(a, b, 1.0);
      links.emplace_back(b, a, 1.0);
    }
  }
  Eigen::SparseMatrix<double> graph(n, n);
  graph.setFromTriplets(links.begin(), links.end());
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> ordering;
  Eigen::AMDOrdering<int>()(graph, ordering);  // position -> block (Eigen's P^-1)
  m_order.assign(ordering.indices().data(), ordering.indices().data() + n);
  m_position.assign(static_cast<size_t>(n), -1);
  for (int j = 0; j < n; ++j) m_position[static_cast<size_t>(m_order[static_cast<size_t>(j)])] = j;
  m_used.resize(static_cast<size_t>(n));
  m_first_column.resize(static_cast<size_t>(n));
  for (int j = 0; j < n; ++j) {
    const auto a = static_cast<size_t>(m_order[static_cast<size_t>(j)]);
    m_first_column[static_cast<size_t>(j)] = column_begin[a];
    m_used[static_cast<size_t>(j)] = column_begin[a + 1] - column_begin[a];
    assert(m_used[static_cast<size_t>(j)] >= 0 && m_used[static_cast<size_t>(j)] <= BLOCK);
  }
}

void BlockCholesky::find_factor_pattern(const std::vector<int>& row_begin, const std::vector<int>& row_column) {
  const int n = block_count();
  // By the elimination tree: column j's rows are its own below it and its children's but j.
  std::vector<std::vector<int>> below(static_cast<size_t>(n));
  for (int a = 0; a < n; ++a) {
    for (int e = row_begin[static_cast<size_t>(a)]; e < row_begin[static_cast<size_t>(a) + 1]; ++e) {
      const int b = row_column[static_cast<size_t>(e)];
      if (b <= a) continue;
      const int pa = m_position[static_cast<size_t>(a)];
      const int pb = m_position[static_cast<size_t>(b)];
      below[static_cast<size_t>(std::min(pa, pb))].push_back(std::max(pa, pb));
    }
  }
  std::vector<std::vector<int>> children(static_cast<size_t>(n));
  m_column_begin.assign(static_cast<size_t>(n) + 1, 0);
  m_row.clear();
  for (int j = 0; j < n; ++j) {
    std::vector<int>& rows = below[static_cast<size_t>(j)];
    for (const int child : children[static_cast<size_t>(j)]) {
      for (int s = m_column_begin[static_cast<size_t>(child)] + 1; s < m_column_begin[static_cast<size_t>(child) + 1];
           ++s) {
        if (m_row[static_cast<size_t>(s)] != j) rows.push_back(m_row[static_cast<size_t>(s)]);
      }
    }
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    if (!rows.empty()) children[static_cast<size_t>(rows.front())].push_back(j);
    m_row.push_back(j);  // the diagonal block
    m_row.insert(m_row.end(), rows.begin(), rows.end());
    m_column_begin[static_cast<size_t>(j) + 1] = static_cast<int>(m_row.size());
  }
  m_factor.assign(m_row.size(), Block::Zero());

  // Per column j, the slots of the blocks (j, k < j).
  m_row_slots_begin.assign(static_cast<size_t>(n) + 1, 0);
  for (int k = 0; k < n; ++k) {
    for (int s = m_column_begin[static_cast<size_t>(k)] + 1; s < m_column_begin[static_cast<size_t>(k) + 1]; ++s) {
      ++m_row_slots_begin[static_cast<size_t>(m_row[static_cast<size_t>(s)]) + 1];
    }
  }
  for (int j = 0; j < n; ++j)
    m_row_slots_begin[static_cast<size_t>(j) + 1] += m_row_slots_begin[static_cast<size_t>(j)];
  m_row_slots.assign(static_cast<size_t>(m_row_slots_begin.back()), -1);
  m_row_slot_column.assign(m_row_slots.size(), -1);
  std::vector<int> next(m_row_slots_begin.begin(), m_row_slots_begin.end() - 1);
  for (int k = 0; k < n; ++k) {  // ascending k: each row's list comes out in column order
    for (int s = m_column_begin[static_cast<size_t>(k)] + 1; s < m_column_begin[static_cast<size_t>(k) + 1]; ++s) {
      const auto at = static_cast<size_t>(next[static_cast<size_t>(m_row[static_cast<size_t>(s)])]++);
      m_row_slots[at] = s;
      m_row_slot_column[at] = k;
    }
  }
}

void BlockCholesky::map_entries(const std::vector<int>& row_begin, const std::vector<int>& row_column) {
  const int n = block_count();
  const auto slot_of = [&](int row, int column) {
    const auto first = m_row.begin() + m_column_begin[static_cast<size_t>(column)];
    const auto last = m_row.begin() + m_column_begin[static_cast<size_t>(column) + 1];
    const auto it = std::lower_bound(first + 1, last, row);
    return row == column ? m_column_begin[static_cast<size_t>(column)] : static_cast<int>(it - m_row.begin());
  };
  m_entry_slot.assign(row_column.size(), -1);
  m_entry_row_block.assign(row_column.size(), -1);
  m_entry_column_block.assign(row_column.size(), -1);
  for (int a = 0; a < n; ++a) {
    for (int e = row_begin[static_cast<size_t>(a)]; e < row_begin[static_cast<size_t>(a) + 1]; ++e) {
      const int b = row_column[static_cast<size_t>(e)];
      if (b < a) continue;
      const int pa = m_position[static_cast<size_t>(a)];
      const int pb = m_position[static_cast<size_t>(b)];
      m_entry_slot[static_cast<size_t>(e)] = slot_of(std::max(pa, pb), std::min(pa, pb));
      m_entry_row_block[static_cast<size_t>(e)] = pa;
      m_entry_column_block[static_cast<size_t>(e)] = pb;
    }
  }
}

bool BlockCholesky::factorize(const std::vector<BlockValues>& blocks) {
  const int n = block_count();
  for (Block& block : m_factor) block.setZero();
  for (int j = 0; j < n; ++j) {  // the padding: the identity on the columns a block does not stand for
    for (int c = m_used[static_cast<size_t>(j)]; c < BLOCK; ++c)
      m_factor[static_cast<size_t>(m_column_begin[static_cast<size_t>(j)])](c, c) = 1.0;
  }
  for (size_t e = 0; e < m_entry_slot.size(); ++e) {
    const int slot = m_entry_slot[e];
    if (slot < 0) continue;
    const int row_block = m_entry_row_block[e];
    const int column_block = m_entry_column_block[e];
    const int rows = m_used[static_cast<size_t>(row_block)];
    const int columns = m_used[static_cast<size_t>(column_block)];
    const Eigen::Map<const Block> value(blocks[e].data());
    Block& target = m_factor[static_cast<size_t>(slot)];
    if (row_block < column_block) {  // stored in the factor's lower triangle as its transpose
      target.topLeftCorner(columns, rows) = value.topLeftCorner(rows, columns).transpose();
    } else {
      target.topLeftCorner(rows, columns) = value.topLeftCorner(rows, columns);
    }
  }
  // Left-looking: column j takes the updates L_ik L_jk^T of the earlier columns k with a block in
  // row j, then its diagonal block is factorized and the blocks below it divided by it.
  for (int j = 0; j < n; ++j) {
    const int first = m_column_begin[static_cast<size_t>(j)];
    const int end = m_column_begin[static_cast<size_t>(j) + 1];
    for (int s = first; s < end; ++s) m_slot_of_row[static_cast<size_t>(m_row[static_cast<size_t>(s)])] = s;
    for (int r = m_row_slots_begin[static_cast<size_t>(j)]; r < m_row_slots_begin[static_cast<size_t>(j) + 1]; ++r) {
      const int slot_jk = m_row_slots[static_cast<size_t>(r)];
      const Block l_jk_transpose = m_factor[static_cast<size_t>(slot_jk)].transpose();
      const int column_end = m_column_begin[static_cast<size_t>(m_row_slot_column[static_cast<size_t>(r)]) + 1];
      for (int s = slot_jk; s < column_end; ++s) {
        m_factor[static_cast<size_t>(m_slot_of_row[static_cast<size_t>(m_row[static_cast<size_t>(s)])])].noalias() -=
            m_factor[static_cast<size_t>(s)] * l_jk_transpose;
      }
    }
    for (int s = first; s < end; ++s) m_slot_of_row[static_cast<size_t>(m_row[static_cast<size_t>(s)])] = -1;
    // The diagonal block is kept as the inverse of its factor: the divisions below and the solves'
    // diagonal steps are then products, which the fixed size unrolls, not substitutions.
    Block& diagonal = m_factor[static_cast<size_t>(first)];
    const Eigen::LLT<Block> llt(diagonal);
    if (llt.info() != Eigen::Success) return false;
    diagonal = llt.matrixL().solve(Block::Identity());
    const Block inverse_transpose = diagonal.transpose();
    for (int s = first + 1; s < end; ++s) {
      Block& block = m_factor[static_cast<size_t>(s)];
      block = (block * inverse_transpose).eval();
    }
  }
  return true;
}

void BlockCholesky::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  using Piece = Eigen::Matrix<double, BLOCK, 1>;
  const int n = block_count();
  m_work.setZero();
  for (int j = 0; j < n; ++j) {
    m_work.segment(BLOCK * j, m_used[static_cast<size_t>(j)]) =
        b.segment(m_first_column[static_cast<size_t>(j)], m_used[static_cast<size_t>(j)]);
  }
  for (int j = 0; j < n; ++j) {  // L y = b
    auto y_j = m_work.segment<BLOCK>(BLOCK * j);
    const int first = m_column_begin[static_cast<size_t>(j)];
    const Piece y = m_factor[static_cast<size_t>(first)] * y_j;
    y_j = y;
    for (int s = first + 1; s < m_column_begin[static_cast<size_t>(j) + 1]; ++s) {
      m_work.segment<BLOCK>(BLOCK * m_row[static_cast<size_t>(s)]).noalias() -= m_factor[static_cast<size_t>(s)] * y;
    }
  }
  for (int j = n - 1; j >= 0; --j) {  // L^T x = y
    const int first = m_column_begin[static_cast<size_t>(j)];
    Piece y = m_work.segment<BLOCK>(BLOCK * j);
    for (int s = first + 1; s < m_column_begin[static_cast<size_t>(j) + 1]; ++s) {
      y.noalias() -=
          m_factor[static_cast<size_t>(s)].transpose() * m_work.segment<BLOCK>(BLOCK * m_row[static_cast<size_t>(s)]);
    }
    m_work.segment<BLOCK>(BLOCK * j).noalias() = m_factor[static_cast<size_t>(first)].transpose() * y;
  }
  x.resize(b.size());
  for (int j = 0; j < n; ++j) {
    x.segment(m_first_column[static_cast<size_t>(j)], m_used[static_cast<size_t>(j)]) =
        m_work.segment(BLOCK * j, m_used[static_cast<size_t>(j)]);
  }
}

}  // namespace tissue
