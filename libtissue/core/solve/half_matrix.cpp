// HalfMatrix (half_matrix.hpp): the compact copy and its product kernel.
#include "core/solve/half_matrix.hpp"
#include "core/system/rows_left.hpp"

#include "core/solve/linear_solver.hpp"
#include "core/system/hot_kernel.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <array>
#include <cstring>
#include <type_traits>

namespace tissue {

void HalfMatrix::derive_pattern(const BlockSparseMatrix& k) {
  // Row c of the copy holds A's blocks (c, r), r >= c, row-major: K's block (r, c) column-major is
  // that block's transpose, so its nine values copied in storage order are (c, r) row-major (K is
  // symmetric). K's rows taken in ascending r give each row c its blocks by ascending column, the
  // diagonal (r = c) first, whatever the order of the slots within K's rows (appended after a cut).
  const int n = k.block_rows();
  m_row_begin.assign(static_cast<size_t>(n) + 1, 0);
  for (int r = 0; r < n; ++r) {
    for (int slot = k.row_begin(r); slot < k.row_begin(r) + k.row_size(r); ++slot) {
      const int c = k.slot_column(slot);
      if (c >= 0 && c <= r) ++m_row_begin[static_cast<size_t>(c) + 1];
    }
  }
  for (int c = 0; c < n; ++c) m_row_begin[static_cast<size_t>(c) + 1] += m_row_begin[static_cast<size_t>(c)];
  const auto blocks = static_cast<size_t>(m_row_begin.back());
  m_column.resize(blocks);
  m_full_slot.resize(blocks);
  std::vector<int>& cursor = m_fill_cursor;
  cursor.assign(m_row_begin.begin(), m_row_begin.end() - 1);
  for (int r = 0; r < n; ++r) {
    for (int slot = k.row_begin(r); slot < k.row_begin(r) + k.row_size(r); ++slot) {
      const int c = k.slot_column(slot);
      if (c < 0 || c > r) continue;
      const auto at = static_cast<size_t>(cursor[static_cast<size_t>(c)]++);
      m_column[at] = r;
      m_full_slot[at] = slot;
    }
  }
  for (int part = 0; part <= PARTS; ++part) {
    m_first_block_row[static_cast<size_t>(part)] = part == PARTS ? n : k.balanced_row_split(part, PARTS);
  }
  m_spill_end = end_block_row(0);
  for (int r = first_block_row(0); r < end_block_row(0); ++r) {
    for (int b = m_row_begin[static_cast<size_t>(r)]; b < m_row_begin[static_cast<size_t>(r) + 1]; ++b) {
      m_spill_end = std::max(m_spill_end, m_column[static_cast<size_t>(b)] + 1);
    }
  }
  m_spill.setZero(3L * n);
  m_source = &k;
  m_pattern_revision = k.pattern_revision();
  m_layout_revision = k.layout_revision();
}

template <class Real>
void HalfMatrix::copy_part(const BlockSparseMatrix& k, double scale, std::vector<Real>& to, int part) {
  const auto end = static_cast<size_t>(m_row_begin[static_cast<size_t>(end_block_row(part))]);
  for (auto b = static_cast<size_t>(m_row_begin[static_cast<size_t>(first_block_row(part))]); b < end; ++b) {
    const double* from = k.block(m_full_slot[b]).data();
    Real* block = &to[9 * b];
    for (int e = 0; e < 9; ++e) block[e] = static_cast<Real>(scale * from[e]);  // (c, r) row-major
  }
}

void HalfMatrix::assign(const ShiftedSystem& system, WorkTeam* team) {
  const BlockSparseMatrix& k = *system.stiffness;
  if (m_source != &k || m_pattern_revision != k.pattern_revision() || m_layout_revision != k.layout_revision() ||
      block_rows() != k.block_rows()) {
    derive_pattern(k);
  }
  const size_t blocks = m_column.size();
  const double s = system.stiffness_scale;
  if (m_precision == MatrixPrecision::single) {
    m_single.resize(9 * blocks + 1);  // + 1: the padding (zero) the product's last column load reads
    m_single.back() = 0.0F;
  } else {
    m_double.resize(9 * blocks + 1);
    m_double.back() = 0.0;
  }
  run_parts(team, PARTS, [&](int part) {
    if (m_precision == MatrixPrecision::single) {
      copy_part(k, s, m_single, part);
    } else {
      copy_part(k, s, m_double, part);
    }
  });
  m_diagonal = *system.diagonal;
  // Of the rows that left the dynamics, those whose row of K (which holds both halves) has no nonzero
  // block but its diagonal: a pass over their rows only (a later cut of a parked tet may join some).
  m_isolated_rows.clear();
  const std::vector<std::uint8_t>* left = system.rows_left;
  const int left_rows = left == nullptr ? 0 : std::min(block_rows(), static_cast<int>(left->size()));
  for (int r = 0; r < left_rows; ++r) {  // (rows past the list are in)
    if (!row_left(left, r)) continue;
    bool joined = false;
    for (int slot = k.row_begin(r); slot < k.row_begin(r) + k.row_size(r) && !joined; ++slot) {
      const int c = k.slot_column(slot);
      joined = c >= 0 && c != r && !k.block(slot).isZero(0.0);
    }
    if (!joined) m_isolated_rows.push_back(r);
  }
}

template <class Real>
Eigen::Matrix3d HalfMatrix::diagonal_block(const std::vector<Real>& values, int row) const {
  const Real* block = &values[9 * static_cast<size_t>(m_row_begin[static_cast<size_t>(row)])];
  Eigen::Matrix3d a;
  for (int e = 0; e < 9; ++e) a(e / 3, e % 3) = static_cast<double>(block[e]);  // row-major
  a.diagonal() += m_diagonal.segment<3>(3L * row);
  return a;
}

void HalfMatrix::solve_isolated_rows(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  for (const int row : m_isolated_rows) {
    const Eigen::Matrix3d a =
        m_precision == MatrixPrecision::single ? diagonal_block(m_single, row) : diagonal_block(m_double, row);
    x.segment<3>(3L * row) = a.ldlt().solve(b.segment<3>(3L * row));
  }
}

long HalfMatrix::streamed_bytes() const {
  const long value_bytes = m_precision == MatrixPrecision::single ? 4 : 8;
  return static_cast<long>(m_column.size()) * (9 * value_bytes + 4);
}

// The helpers are always inlined into the kernel's clones: -Wpsabi's note (a 32-byte vector
// passed or returned without AVX) concerns calls that never happen. GCC issues it while it
// generates the clones, at the end of the file, so it stays off to the end (clang warns alike).
#pragma GCC diagnostic ignored "-Wpsabi"  // (clang too)

namespace {

// Four doubles in one AVX2 register (two SSE registers in the baseline clone). A block's column is
// loaded as four consecutive values: its three entries and the next one (the next column's first,
// or the next block's, or the padding value after the last block), a lane whose results are never
// used or, multiplied by x's zero fourth lane, add zero.
using Lanes = double __attribute__((vector_size(32)));

[[gnu::always_inline]] inline Lanes load_lanes(const double* from) {
  Lanes lanes;
  std::memcpy(&lanes, from, sizeof(lanes));
  return lanes;
}

// Four floats widened one by one, which the AVX2 clone turns into one vcvtps2pd: a float vector
// converted whole (__builtin_convertvector) is split into SSE2-sized halves before the function
// is cloned, and the single-precision product took up to twice the double one's time (now about
// the same; docs/BENCHMARKS.md, issue 40).
[[gnu::always_inline]] inline Lanes load_lanes(const float* from) {
  return Lanes{static_cast<double>(from[0]), static_cast<double>(from[1]), static_cast<double>(from[2]),
               static_cast<double>(from[3])};
}

// COLUMN_LANES doubles: lane l of a block row's component i is column l's entry (multiply_columns),
// as two four-lane halves (a wider generic vector times a scalar goes through the stack in GCC's
// AVX2 clone, ~40x slower).
struct ColumnLanes {
  Lanes low, high;
};
static_assert(HalfMatrix::COLUMN_LANES == 8, "two halves of four lanes");

[[gnu::always_inline]] inline ColumnLanes load_column_lanes(const double* from) {
  return {load_lanes(from), load_lanes(from + 4)};
}
[[gnu::always_inline]] inline ColumnLanes operator*(double scale, const ColumnLanes& lanes) {
  return {scale * lanes.low, scale * lanes.high};
}
[[gnu::always_inline]] inline ColumnLanes operator+(const ColumnLanes& a, const ColumnLanes& b) {
  return {a.low + b.low, a.high + b.high};
}
[[gnu::always_inline]] inline ColumnLanes& operator+=(ColumnLanes& a, const ColumnLanes& b) {
  a.low += b.low;
  a.high += b.high;
  return a;
}
[[gnu::always_inline]] inline void add_column_lanes(double* to, const ColumnLanes& lanes) {
  const Lanes low = load_lanes(to) + lanes.low, high = load_lanes(to + 4) + lanes.high;
  std::memcpy(to, &low, sizeof(low));
  std::memcpy(to + 4, &high, sizeof(high));
}

}  // namespace

template <class Real>
TISSUE_HOT_KERNEL void HalfMatrix::multiply_lanes_rows(const Real* __restrict values, double* __restrict y,
                                                       int part) const {
  constexpr long ROW = 3L * COLUMN_LANES;
  constexpr long PREFETCH_VALUES = 1024 / sizeof(Real);
  const int first = first_block_row(part);
  const int end = end_block_row(part);
  const int* __restrict column = m_column.data();
  const int* __restrict row_begin = m_row_begin.data();
  const double* __restrict d = m_diagonal.data();
  const double* __restrict x = m_lanes_in.data();
  double* __restrict spill = m_lanes_spill.data();
  std::fill(y + ROW * first, y + ROW * end, 0.0);
  clear_spill(spill, ROW, part);
  for (int r = first; r < end; ++r) {
    const double* x_r = x + ROW * r;
    const ColumnLanes x0 = load_column_lanes(x_r), x1 = load_column_lanes(x_r + COLUMN_LANES),
                      x2 = load_column_lanes(x_r + 2 * COLUMN_LANES);
    const Real* b = values + 9L * row_begin[r];
    // The diagonal block (symmetric) and d, then the upper blocks: each B x_c into the row's own
    // sums, B^T x_r into row c's (B row-major: b[3 i + j] = B_ij).
    ColumnLanes acc0 = (double(b[0]) + d[3 * r]) * x0 + double(b[1]) * x1 + double(b[2]) * x2;
    ColumnLanes acc1 = double(b[3]) * x0 + (double(b[4]) + d[3 * r + 1]) * x1 + double(b[5]) * x2;
    ColumnLanes acc2 = double(b[6]) * x0 + double(b[7]) * x1 + (double(b[8]) + d[3 * r + 2]) * x2;
    for (int k = row_begin[r] + 1; k < row_begin[r + 1]; ++k) {
      b = values + 9L * k;
      __builtin_prefetch(b + PREFETCH_VALUES);
      const int c = column[k];
      const double* x_c = x + ROW * c;
      const double b00 = b[0], b01 = b[1], b02 = b[2], b10 = b[3], b11 = b[4], b12 = b[5], b20 = b[6], b21 = b[7],
                   b22 = b[8];
      const ColumnLanes c0 = load_column_lanes(x_c), c1 = load_column_lanes(x_c + COLUMN_LANES),
                        c2 = load_column_lanes(x_c + 2 * COLUMN_LANES);
      acc0 += b00 * c0 + b01 * c1 + b02 * c2;
      acc1 += b10 * c0 + b11 * c1 + b12 * c2;
      acc2 += b20 * c0 + b21 * c1 + b22 * c2;
      double* to = (c < end ? y : spill) + ROW * c;
      add_column_lanes(to, b00 * x0 + b10 * x1 + b20 * x2);
      add_column_lanes(to + COLUMN_LANES, b01 * x0 + b11 * x1 + b21 * x2);
      add_column_lanes(to + 2 * COLUMN_LANES, b02 * x0 + b12 * x1 + b22 * x2);
    }
    double* y_r = y + ROW * r;
    add_column_lanes(y_r, acc0);
    add_column_lanes(y_r + COLUMN_LANES, acc1);
    add_column_lanes(y_r + 2 * COLUMN_LANES, acc2);
  }
}

void HalfMatrix::multiply_columns(const Eigen::Ref<const Eigen::MatrixXd>& x, RowMajorMatrix& y, WorkTeam* team) const {
  constexpr long ROW = 3L * COLUMN_LANES;
  const long rows = block_rows();
  y.resize(3 * rows, x.cols());
  m_lanes_in.resize(static_cast<size_t>(ROW * rows));
  m_lanes_spill.resize(static_cast<size_t>(ROW * rows));
  // A block row's 24 lanes (component i, lane l at 8 i + l) are its three rows of X in row-major
  // order: entry e of column l at COLUMN_LANES e + l. Y of COLUMN_LANES columns is written in place.
  const long entries = 3 * rows;
  const bool in_place = x.cols() == COLUMN_LANES;
  if (!in_place) m_lanes_out.resize(static_cast<size_t>(ROW * rows));
  double* out = in_place ? y.data() : m_lanes_out.data();
  for (Eigen::Index first = 0; first < x.cols(); first += COLUMN_LANES) {
    const auto lanes = static_cast<int>(std::min<Eigen::Index>(COLUMN_LANES, x.cols() - first));
    std::array<const double*, COLUMN_LANES> columns{};
    for (int l = 0; l < lanes; ++l) columns[static_cast<size_t>(l)] = &x.coeffRef(0, first + l);
    for (long e = 0; e < entries; ++e) {
      double* to = m_lanes_in.data() + COLUMN_LANES * e;
      for (int l = 0; l < COLUMN_LANES; ++l) to[l] = l < lanes ? columns[static_cast<size_t>(l)][e] : 0.0;
    }
    run_parts(team, PARTS, [&](int part) {
      if (m_precision == MatrixPrecision::single) {
        multiply_lanes_rows(m_single.data(), out, part);
      } else {
        multiply_lanes_rows(m_double.data(), out, part);
      }
    });
    run_parts(team, PARTS, [&](int part) { add_spill(out, m_lanes_spill.data(), ROW, part); });
    if (in_place) continue;
    for (long e = 0; e < entries; ++e) {
      for (int l = 0; l < lanes; ++l) y(e, first + l) = out[COLUMN_LANES * e + l];
    }
  }
}

template <class Real>
TISSUE_HOT_KERNEL void HalfMatrix::multiply_rows(const Real* __restrict values, const double* __restrict x,
                                                 double* __restrict y, int part) const {
  const int first = first_block_row(part);
  const int end = end_block_row(part);
  const int last_row = block_rows() - 1;
  constexpr long PREFETCH_VALUES = 1024 / sizeof(Real);
  const int* __restrict column = m_column.data();
  const int* __restrict row_begin = m_row_begin.data();
  const double* __restrict d = m_diagonal.data();
  double* __restrict spill = m_spill.data();
  std::fill(y + 3L * first, y + 3L * end, 0.0);
  clear_spill(spill, 3, part);
  for (int r = first; r < end; ++r) {
    const double x0 = x[3 * r], x1 = x[3 * r + 1], x2 = x[3 * r + 2];
    const int begin = row_begin[r];
    const int stop = row_begin[r + 1];
    // Row i of y_r gathered lane-wise over the row's blocks (acc_i += B_row_i * x_c), summed
    // across lanes once at the row's end; lane 3 carries a neighbour's product and is never read.
    Lanes acc0{}, acc1{}, acc2{};
    // One block: its terms for this row, and B^T x_r = x_r0 row0 + x_r1 row1 + x_r2 row2 (lanes
    // 0-2) for row c in `target`. x_c is read four wide except for the last row (`Narrow`).
    const auto add_block = [&](int k, double* __restrict target, auto narrow) {
      const Real* b = values + 9L * k;
      __builtin_prefetch(b + PREFETCH_VALUES);
      const int c = column[k];
      const double* xc = x + 3L * c;
      Lanes x_c;
      if constexpr (decltype(narrow)::value) {
        x_c = Lanes{xc[0], xc[1], xc[2], 0.0};
      } else {
        x_c = load_lanes(xc);
      }
      const Lanes row0 = load_lanes(b), row1 = load_lanes(b + 3), row2 = load_lanes(b + 6);
      acc0 += row0 * x_c;
      acc1 += row1 * x_c;
      acc2 += row2 * x_c;
      const Lanes t = row0 * x0 + row1 * x1 + row2 * x2;
      double* to = target + 3L * c;
      to[0] += t[0];
      to[1] += t[1];
      to[2] += t[2];
    };
    // The row's columns ascend: those of later parts' rows (part 0's terms for them go to the
    // spill) are its last blocks, and the last row's column, if any, is its very last.
    const bool last_column = stop > begin + 1 && column[stop - 1] == last_row;
    const int wide_stop = last_column ? stop - 1 : stop;
    int spill_from = wide_stop;
    while (spill_from > begin + 1 && column[spill_from - 1] >= end) --spill_from;
    for (int k = begin + 1; k < spill_from; ++k) add_block(k, y, std::false_type{});
    for (int k = spill_from; k < wide_stop; ++k) add_block(k, spill, std::false_type{});
    if (last_column) add_block(stop - 1, last_row < end ? y : spill, std::true_type{});
    // The diagonal block (symmetric) and d.
    const Real* b = values + 9L * begin;
    const Lanes diagonal = load_lanes(b) * x0 + load_lanes(b + 3) * x1 + load_lanes(b + 6) * x2;
    y[3 * r] += diagonal[0] + d[3 * r] * x0 + (acc0[0] + acc0[1] + acc0[2]);
    y[3 * r + 1] += diagonal[1] + d[3 * r + 1] * x1 + (acc1[0] + acc1[1] + acc1[2]);
    y[3 * r + 2] += diagonal[2] + d[3 * r + 2] * x2 + (acc2[0] + acc2[1] + acc2[2]);
  }
}

void HalfMatrix::multiply_part(const Eigen::VectorXd& x, Eigen::VectorXd& y, int part) const {
  if (m_precision == MatrixPrecision::single) {
    multiply_rows(m_single.data(), x.data(), y.data(), part);
  } else {
    multiply_rows(m_double.data(), x.data(), y.data(), part);
  }
}

void HalfMatrix::clear_spill(double* spill, long row_width, int part) const {
  if (part == 0) std::fill(spill + row_width * end_block_row(0), spill + row_width * m_spill_end, 0.0);
}

void HalfMatrix::add_spill(double* y, const double* spill, long row_width, int part) const {
  if (part == 0) return;
  const long stop = row_width * std::min(end_block_row(part), m_spill_end);
  for (long e = row_width * first_block_row(part); e < stop; ++e) y[e] += spill[e];
}

void HalfMatrix::finish_part(Eigen::VectorXd& y, int part) const { add_spill(y.data(), m_spill.data(), 3, part); }

void HalfMatrix::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, WorkTeam* team) const {
  y.resize(3L * block_rows());
  run_parts(team, PARTS, [&](int part) { multiply_part(x, y, part); });
  run_parts(team, PARTS, [&](int part) { finish_part(y, part); });
}

}  // namespace tissue
