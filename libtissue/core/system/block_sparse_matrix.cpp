// BlockSparseMatrix: block-row storage with reserved room, the product kernel used by PCG,
// and the growth operations used by XFEM enrichment.
//
// Storage: the rows occupy consecutive slot ranges [row_begin, row_begin + row_capacity);
// the first row_size slots of a range are in use. After the last row comes the spare room for
// block_row_capacity() - block_rows() spare rows (m_spare_row_capacity slots each), which
// append_block_row() hands out in order, as a pool: a row may take more than its share. Unused
// slots hold column -1 and zero values, so a newly used slot is a zero block.
#include "core/system/block_sparse_matrix.hpp"

#include "core/index_cast.hpp"
#include "core/system/hot_kernel.hpp"
#include "core/system/resident_reserve.hpp"
#include "core/system/work_team.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace tissue {

namespace {

// Slots given to each spare row of a matrix that started empty (no mean row size to go by):
// a vertex of a tet mesh typically couples to 10-20 others.
constexpr int DEFAULT_SPARE_ROW_CAPACITY = 16;

int spare_row_count(double fraction, int rows) {
  return static_cast<int>(std::ceil(fraction * static_cast<double>(rows)));
}

}  // namespace

void BlockSparseMatrix::refuse_on_a_view(const char* operation) const {
  if (m_viewed != nullptr) {
    throw std::logic_error(std::string("BlockSparseMatrix::") + operation +
                           ": a view of another matrix's rows (view_rows_of) is read only");
  }
}

BlockSparseMatrix::BlockSparseMatrix(const std::vector<std::vector<int>>& pattern, Reserve reserve,
                                     const std::vector<int>& min_row_capacity)
    : m_reserve(reserve) {
  if (!(reserve.extra_row_fraction >= 0.0) || !std::isfinite(reserve.extra_row_fraction) ||
      reserve.row_capacity_factor < 1 || reserve.spare_row_capacity < 0) {
    throw std::invalid_argument(
        "BlockSparseMatrix: reserve needs extra_row_fraction >= 0, row_capacity_factor >= 1 and "
        "spare_row_capacity >= 0");
  }
  const int n = static_cast<int>(pattern.size());
  if (!min_row_capacity.empty() && min_row_capacity.size() != pattern.size()) {
    throw std::invalid_argument("BlockSparseMatrix: min_row_capacity has " + std::to_string(min_row_capacity.size()) +
                                " entries for " + std::to_string(n) + " rows");
  }

  // Sorted, duplicate-free columns per row, diagonal included.
  std::vector<std::vector<int>> columns(to_size(n));
  std::vector<int> capacity(to_size(n));
  long total_capacity = 0;
  for (int r = 0; r < n; ++r) {
    std::vector<int>& row = columns[to_size(r)];
    row = pattern[to_size(r)];
    for (const int c : row) {
      if (c < 0 || c >= n) {
        throw std::invalid_argument("BlockSparseMatrix: block row " + std::to_string(r) + " lists column " +
                                    std::to_string(c) + ", outside [0, " + std::to_string(n) + ")");
      }
    }
    row.push_back(r);
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
    capacity[to_size(r)] = static_cast<int>(row.size()) * reserve.row_capacity_factor;
    if (!min_row_capacity.empty()) capacity[to_size(r)] = std::max(capacity[to_size(r)], min_row_capacity[to_size(r)]);
    total_capacity += capacity[to_size(r)];
  }

  const int spare_rows = spare_row_count(reserve.extra_row_fraction, n);
  m_spare_row_capacity = reserve.spare_row_capacity > 0 ? reserve.spare_row_capacity
                         : n > 0                        ? static_cast<int>((total_capacity + n - 1) / n)
                                                        : DEFAULT_SPARE_ROW_CAPACITY;
  const long slot_count = total_capacity + static_cast<long>(spare_rows) * m_spare_row_capacity;
  if (slot_count > (1L << 31) / 9 - 1)
    throw std::length_error("BlockSparseMatrix: too many blocks for int slot indices");

  m_row_begin.resize(to_size(n));
  m_row_size.resize(to_size(n));
  m_row_capacity.resize(to_size(n));
  m_diagonal_slot.resize(to_size(n));
  reserve_slots(static_cast<size_t>(slot_count));
  m_column.assign(static_cast<size_t>(slot_count), -1);
  m_values.assign(9 * static_cast<size_t>(slot_count), 0.0);

  int begin = 0;
  for (int r = 0; r < n; ++r) {
    const std::vector<int>& row = columns[to_size(r)];
    const int size = static_cast<int>(row.size());
    m_row_begin[to_size(r)] = begin;
    m_row_size[to_size(r)] = size;
    m_row_capacity[to_size(r)] = capacity[to_size(r)];
    for (int k = 0; k < size; ++k) {
      m_column[to_size(begin + k)] = row[to_size(k)];
      if (row[to_size(k)] == r) m_diagonal_slot[to_size(r)] = begin + k;
    }
    m_nonzero_blocks += size;
    begin += m_row_capacity[to_size(r)];
  }
  m_block_row_capacity = n + spare_rows;
}

int BlockSparseMatrix::find_slot(int row, int col) const {
  if (row < 0 || row >= block_rows()) return -1;
  const int begin = m_row_begin[to_size(row)];
  const int end = begin + m_row_size[to_size(row)];
  for (int k = begin; k < end; ++k) {
    if (m_column[to_size(k)] == col) return k;
  }
  return -1;
}

void BlockSparseMatrix::set_zero() { set_zero(nullptr); }

void BlockSparseMatrix::set_zero(WorkTeam* team) {
  refuse_on_a_view("set_zero");
  // Only the used slots: unused slots are zero already (relayout and insert keep them so).
  const int parts = team_parts(team);
  run_parts(team, parts, [&](int part) {
    double* values = m_values.data();
    const int end = balanced_row_split(part + 1, parts);
    for (int r = balanced_row_split(part, parts); r < end; ++r) {
      double* first = values + 9 * to_size(m_row_begin[to_size(r)]);
      std::fill(first, first + 9 * to_size(m_row_size[to_size(r)]), 0.0);
    }
  });
}

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  const int n = block_rows();
  if (x.size() != rows()) {
    throw std::invalid_argument("BlockSparseMatrix::multiply: x has length " + std::to_string(x.size()) +
                                ", expected " + std::to_string(rows()));
  }
  if (&x == &y) throw std::invalid_argument("BlockSparseMatrix::multiply: x and y must be different vectors");
  y.resize(rows());  // no-op (and no allocation) when the size is right
  multiply_rows(x, y, 0, n);
}

void BlockSparseMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, WorkTeam* team) const {
  if (team == nullptr || team->size() < 2) {
    multiply(x, y);
    return;
  }
  if (x.size() != rows()) {
    throw std::invalid_argument("BlockSparseMatrix::multiply: x has length " + std::to_string(x.size()) +
                                ", expected " + std::to_string(rows()));
  }
  if (&x == &y) throw std::invalid_argument("BlockSparseMatrix::multiply: x and y must be different vectors");
  y.resize(rows());
  const int parts = team->size();
  run_parts(team, parts, [&](int part) {
    multiply_rows(x, y, balanced_row_split(part, parts), balanced_row_split(part + 1, parts));
  });
}

int BlockSparseMatrix::balanced_row_split(int part, int parts) const {
  if (part <= 0) return 0;
  if (part >= parts) return block_rows();  // also the end of the only part when parts <= 1
  const long wanted = static_cast<long>(m_nonzero_blocks) * part / parts;
  long blocks = 0;
  int row = 0;
  for (; row < block_rows() && blocks < wanted; ++row) blocks += m_row_size[to_size(row)];
  return row;
}

TISSUE_HOT_KERNEL void BlockSparseMatrix::multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y,
                                                        int first_block_row, int end_block_row) const {
  // The inner kernel of PCG: plain loops over raw arrays, three accumulators per block row,
  // so that the compiler keeps them in registers and the slots are streamed once, in order.
  const double* __restrict xv = x.data();
  double* __restrict yv = y.data();
  const double* __restrict values = this->values();
  const int* __restrict column = m_column.data();
  const int* row_begin = m_row_begin.data();
  const int* row_size = m_row_size.data();
  // Two blocks per turn into two sets of accumulators: the additions into y0..y2 form the loop's
  // dependency chain, and two independent chains keep the adders busy (~25% faster than one).
  for (int r = first_block_row; r < end_block_row; ++r) {
    const int begin = row_begin[r];
    const int end = begin + row_size[r];
    double y0 = 0.0, y1 = 0.0, y2 = 0.0;
    double z0 = 0.0, z1 = 0.0, z2 = 0.0;
    int k = begin;
    for (; k + 1 < end; k += 2) {
      const double* b = values + 9 * static_cast<ptrdiff_t>(k);  // column-major 3x3, two in a row
      const double* xc = xv + 3 * static_cast<ptrdiff_t>(column[k]);
      const double* xd = xv + 3 * static_cast<ptrdiff_t>(column[k + 1]);
      y0 += b[0] * xc[0] + b[3] * xc[1] + b[6] * xc[2];
      y1 += b[1] * xc[0] + b[4] * xc[1] + b[7] * xc[2];
      y2 += b[2] * xc[0] + b[5] * xc[1] + b[8] * xc[2];
      z0 += b[9] * xd[0] + b[12] * xd[1] + b[15] * xd[2];
      z1 += b[10] * xd[0] + b[13] * xd[1] + b[16] * xd[2];
      z2 += b[11] * xd[0] + b[14] * xd[1] + b[17] * xd[2];
    }
    if (k < end) {
      const double* b = values + 9 * static_cast<ptrdiff_t>(k);
      const double* xc = xv + 3 * static_cast<ptrdiff_t>(column[k]);
      y0 += b[0] * xc[0] + b[3] * xc[1] + b[6] * xc[2];
      y1 += b[1] * xc[0] + b[4] * xc[1] + b[7] * xc[2];
      y2 += b[2] * xc[0] + b[5] * xc[1] + b[8] * xc[2];
    }
    yv[3 * r] = y0 + z0;
    yv[3 * r + 1] = y1 + z1;
    yv[3 * r + 2] = y2 + z2;
  }
}

void BlockSparseMatrix::view_rows_of(const BlockSparseMatrix& k, const std::vector<int>& rows,
                                     const std::vector<int>& index_of_row) {
  if (index_of_row.size() != to_size(k.block_rows())) {
    throw std::invalid_argument("BlockSparseMatrix::view_rows_of: index_of_row has " +
                                std::to_string(index_of_row.size()) + " entries for " + std::to_string(k.block_rows()) +
                                " rows");
  }
  const auto n = rows.size();
  m_row_begin.resize(n);
  m_row_size.resize(n);
  m_row_capacity.resize(n);
  m_diagonal_slot.resize(n);
  m_column.assign(k.m_column.size(), -1);
  m_values.clear();
  m_viewed = &k;
  m_nonzero_blocks = 0;
  for (size_t c = 0; c < n; ++c) {
    const auto r = to_size(rows[c]);
    if (index_of_row[r] != static_cast<int>(c)) {
      throw std::invalid_argument("BlockSparseMatrix::view_rows_of: row " + std::to_string(r) + " is not numbered " +
                                  std::to_string(c));
    }
    const int begin = k.m_row_begin[r];
    m_row_begin[c] = begin;
    m_row_size[c] = k.m_row_size[r];
    m_row_capacity[c] = k.m_row_capacity[r];
    m_diagonal_slot[c] = k.m_diagonal_slot[r];
    for (int slot = begin; slot < begin + k.m_row_size[r]; ++slot) {
      const int column = index_of_row[to_size(k.m_column[to_size(slot)])];
      if (column < 0) {
        throw std::invalid_argument("BlockSparseMatrix::view_rows_of: row " + std::to_string(r) +
                                    " has a block with row " + std::to_string(k.m_column[to_size(slot)]) +
                                    ", which is left out");
      }
      m_column[to_size(slot)] = column;
    }
    m_nonzero_blocks += k.m_row_size[r];
  }
  m_relayout_slot_map.clear();
  m_spare_row_capacity = 0;
  m_block_row_capacity = static_cast<int>(n);
  m_reserve = k.m_reserve;
  ++m_pattern_revision;
  ++m_layout_revision;
}

void BlockSparseMatrix::diagonal(Eigen::VectorXd& diagonal) const {
  const int n = block_rows();
  diagonal.resize(rows());
  for (int r = 0; r < n; ++r) diagonal.segment<3>(3 * r) = block(m_diagonal_slot[to_size(r)]).diagonal();
}

void BlockSparseMatrix::reserve_slots(size_t slots) {
  if (m_column.capacity() >= slots) return;
  reserve_resident(m_column, 2 * slots);
  reserve_resident(m_values, 9 * m_column.capacity());
}

// In place, from the last row to the first: a row's room never shrinks, so each row moves to a slot
// at or after its old first one and its new room ends where the next row's, already moved, begins;
// its blocks are read out (sorted by column) before they are written back. A second buffer (as
// before) meant, whenever the storage grew, fresh pages and a useless copy of the layout before the
// last: a frog's re-layout took 1.3-1.7 ms, of which 0.16 ms moved its blocks (docs/BENCHMARKS.md).
void BlockSparseMatrix::relayout(const std::vector<std::pair<int, int>>& min_capacity, int spare_rows) {
  const int n = block_rows();
  if (m_spare_row_capacity < 1) m_spare_row_capacity = DEFAULT_SPARE_ROW_CAPACITY;

  std::vector<int> capacity(to_size(n));
  for (int r = 0; r < n; ++r) {
    const int size = m_row_size[to_size(r)];
    capacity[to_size(r)] = std::max({m_row_capacity[to_size(r)], size * m_reserve.row_capacity_factor, 1});
  }
  for (const auto& [row, cap] : min_capacity) capacity[to_size(row)] = std::max(capacity[to_size(row)], cap);
  long slot_count = 0;
  for (int r = 0; r < n; ++r) slot_count += capacity[to_size(r)];
  slot_count += static_cast<long>(spare_rows) * m_spare_row_capacity;
  if (slot_count > (1L << 31) / 9 - 1)
    throw std::length_error("BlockSparseMatrix: too many blocks for int slot indices");
  std::vector<int> row_begin(to_size(n));
  for (int r = 1; r < n; ++r) row_begin[to_size(r)] = row_begin[to_size(r - 1)] + capacity[to_size(r - 1)];

  // The old rows end here; every slot after it is unused (zero), and so is storage added below.
  const int old_rows_end = row_room();
  const size_t old_slots = m_column.size();
  const auto slots = static_cast<size_t>(slot_count);
  if (slots > old_slots) {
    reserve_slots(slots);
    m_column.resize(slots, -1);
    m_values.resize(9 * slots, 0.0);
  }
  m_relayout_slot_map.assign(old_slots, -1);
  std::vector<std::pair<int, int>> order;  // (column, old slot) of one row
  std::vector<double> row_values;          // its blocks in that order
  for (int r = n - 1; r >= 0; --r) {
    const int old_begin = m_row_begin[to_size(r)];
    const int size = m_row_size[to_size(r)];
    order.clear();
    for (int k = 0; k < size; ++k) order.emplace_back(m_column[to_size(old_begin + k)], old_begin + k);
    std::sort(order.begin(), order.end());  // appended blocks return to column order: better locality
    row_values.resize(9 * to_size(size));
    for (int k = 0; k < size; ++k) {
      std::copy_n(&m_values[9 * to_size(order[to_size(k)].second)], 9, &row_values[9 * to_size(k)]);
    }
    const int begin = row_begin[to_size(r)];
    for (int k = 0; k < size; ++k) {
      const int slot = begin + k;
      m_column[to_size(slot)] = order[to_size(k)].first;
      std::copy_n(&row_values[9 * to_size(k)], 9, &m_values[9 * to_size(slot)]);
      m_relayout_slot_map[to_size(order[to_size(k)].second)] = slot;
      if (order[to_size(k)].first == r) m_diagonal_slot[to_size(r)] = slot;
    }
    // The rest of its room may hold blocks of the old layout (its own, the next rows'): cleared.
    const int clear_end = std::min(begin + capacity[to_size(r)], old_rows_end);
    for (int slot = begin + size; slot < clear_end; ++slot) m_column[to_size(slot)] = -1;
    if (clear_end > begin + size) {
      std::fill(m_values.begin() + 9 * static_cast<long>(begin + size), m_values.begin() + 9 * static_cast<long>(clear_end), 0.0);
    }
  }
  if (slots < old_slots) {  // fewer spare rows: the tail is unused
    m_column.resize(slots);
    m_values.resize(9 * slots);
  }

  m_row_begin = std::move(row_begin);
  m_row_capacity = std::move(capacity);
  m_block_row_capacity = n + spare_rows;
  ++m_layout_revision;
  ++m_pattern_revision;
}

bool BlockSparseMatrix::remove_blocks(const std::vector<std::uint8_t>& keep, RowRoom room) {
  refuse_on_a_view("remove_blocks");
  if (keep.size() != m_column.size()) {
    throw std::invalid_argument("BlockSparseMatrix::remove_blocks: " + std::to_string(keep.size()) + " marks for " +
                                std::to_string(m_column.size()) + " slots");
  }
  const size_t old_slots = m_column.size();
  m_relayout_slot_map.assign(old_slots, -1);
  bool changed = false;
  // Packed, each row moves to a slot at or before its old first one (the rows before it shrink or
  // keep their room), so the rows go front to back and a block never lands on one not yet read.
  int packed_begin = 0;
  for (int r = 0; r < block_rows(); ++r) {
    const int old_begin = m_row_begin[to_size(r)];
    const int begin = room == RowRoom::packed ? packed_begin : old_begin;
    const int size = m_row_size[to_size(r)];
    int kept = 0;
    for (int k = 0; k < size; ++k) {
      const int slot = old_begin + k;
      if (keep[to_size(slot)] == 0 && m_column[to_size(slot)] != r) {
        changed = true;
        continue;
      }
      const int target = begin + kept++;  // never after `slot`: blocks keep their order
      if (target != slot) {
        m_column[to_size(target)] = m_column[to_size(slot)];
        std::copy_n(&m_values[9 * to_size(slot)], 9, &m_values[9 * to_size(target)]);
      }
      m_relayout_slot_map[to_size(slot)] = target;
      if (m_column[to_size(target)] == r) m_diagonal_slot[to_size(r)] = target;
    }
    // The old blocks' slots that no block of this row now holds are unused (column -1, zeros); the
    // rest of its room was already.
    for (int slot = std::max(begin + kept, old_begin); slot < old_begin + size; ++slot) {
      m_column[to_size(slot)] = -1;
      std::fill_n(&m_values[9 * to_size(slot)], 9, 0.0);
    }
    m_nonzero_blocks -= size - kept;
    m_row_size[to_size(r)] = kept;
    if (room == RowRoom::packed) {
      changed = changed || begin != old_begin || m_row_capacity[to_size(r)] != kept;
      m_row_begin[to_size(r)] = begin;
      m_row_capacity[to_size(r)] = kept;
      packed_begin += kept;
    }
  }
  if (room == RowRoom::packed) {  // the spare rows' room follows the rows again
    const size_t slots =
        to_size(packed_begin) + to_size(m_block_row_capacity - block_rows()) * to_size(m_spare_row_capacity);
    if (slots < old_slots) {
      m_column.resize(slots);
      m_values.resize(9 * slots);
    }
  }
  if (changed) {
    ++m_layout_revision;
    ++m_pattern_revision;
  }
  return changed;
}

int BlockSparseMatrix::row_room() const {
  const int n = block_rows();
  return n == 0 ? 0 : m_row_begin[to_size(n - 1)] + m_row_capacity[to_size(n - 1)];
}

int BlockSparseMatrix::append_block_row(int min_capacity) {
  refuse_on_a_view("append_block_row");
  int n = block_rows();
  int begin = row_room();
  int capacity = std::max(m_spare_row_capacity, min_capacity);
  if (n >= m_block_row_capacity || capacity < 1 || begin + capacity > slot_capacity()) {
    // Out of spare room: reserve a fresh batch, as the constructor did, so that the next
    // enrichments again grow in place; at least n/4 + 1 rows, so that growing row by row from a
    // small (or empty) matrix re-lays out O(log n) times, not n times. The spare rows' room is a
    // pool: a row that takes more than the spare-row capacity leaves less for the others.
    const int per_row = m_spare_row_capacity > 0 ? m_spare_row_capacity : DEFAULT_SPARE_ROW_CAPACITY;
    const int rows_for_this_one = (std::max(min_capacity, per_row) + per_row - 1) / per_row;
    relayout({}, std::max(spare_row_count(m_reserve.extra_row_fraction, n), n / 4 + 1) + rows_for_this_one);
    capacity = std::max(m_spare_row_capacity, min_capacity);
    begin = row_room();
  }
  m_row_begin.push_back(begin);
  m_row_size.push_back(1);
  m_row_capacity.push_back(capacity);
  m_diagonal_slot.push_back(begin);
  m_column[to_size(begin)] = n;
  std::fill_n(&m_values[9 * to_size(begin)], 9, 0.0);
  ++m_nonzero_blocks;
  ++m_pattern_revision;
  return n;
}

int BlockSparseMatrix::insert_block(int row, int col) {
  refuse_on_a_view("insert_block");
  const int n = block_rows();
  if (row < 0 || row >= n || col < 0 || col >= n) {
    throw std::out_of_range("BlockSparseMatrix::insert_block: block (" + std::to_string(row) + ", " +
                            std::to_string(col) + ") outside a matrix of " + std::to_string(n) + " block rows");
  }
  const int existing = find_slot(row, col);
  if (existing >= 0) return existing;

  if (m_row_size[to_size(row)] == m_row_capacity[to_size(row)]) {
    relayout({{row, 2 * m_row_size[to_size(row)]}}, m_block_row_capacity - n);  // geometric growth
  }
  const int slot = m_row_begin[to_size(row)] + m_row_size[to_size(row)];
  m_column[to_size(slot)] = col;
  std::fill_n(&m_values[9 * to_size(slot)], 9, 0.0);
  ++m_row_size[to_size(row)];
  ++m_nonzero_blocks;
  ++m_pattern_revision;
  return slot;
}

bool BlockSparseMatrix::reserve_room(const std::vector<std::pair<int, int>>& row_extra) {
  refuse_on_a_view("reserve_room");
  const int n = block_rows();
  std::vector<std::pair<int, int>> needed;  // (row, blocks it must hold)
  std::vector<int> extra_of;
  for (const auto& [row, extra] : row_extra) {
    if (row < 0 || row >= n || extra < 0) {
      throw std::out_of_range("BlockSparseMatrix::reserve_room: row " + std::to_string(row) + " (of " +
                              std::to_string(n) + ") with " + std::to_string(extra) + " extra blocks");
    }
    if (extra_of.empty()) extra_of.assign(to_size(n), 0);
    extra_of[to_size(row)] += extra;
  }
  for (int r = 0; r < static_cast<int>(extra_of.size()); ++r) {
    const int wanted = m_row_size[to_size(r)] + extra_of[to_size(r)];
    if (extra_of[to_size(r)] > 0 && wanted > m_row_capacity[to_size(r)]) {
      needed.emplace_back(r, std::max(wanted, 2 * m_row_size[to_size(r)]));  // at least doubled: geometric
    }
  }
  if (needed.empty()) return false;
  relayout(needed, m_block_row_capacity - n);
  return true;
}

}  // namespace tissue
