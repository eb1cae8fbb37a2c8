// Tests of BlockSparseMatrix: the product against a dense reference, the reserved room
// (slots stay valid while growth fits), re-layout on overflow, spare rows, and the pattern order.
#include "core/system/block_sparse_matrix.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <sys/mman.h>
#include <unistd.h>

namespace tissue {
namespace {

using BlockMap = std::map<std::pair<int, int>, Eigen::Matrix3d>;
using Pattern = std::vector<std::vector<int>>;

// A random structurally symmetric pattern: each row couples to a few random others.
std::vector<std::vector<int>> random_symmetric_pattern(int n, int couplings_per_row, std::mt19937& rng) {
  std::vector<std::vector<int>> pattern(static_cast<size_t>(n));
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int r = 0; r < n; ++r) {
    for (int k = 0; k < couplings_per_row; ++k) {
      const int c = pick(rng);
      pattern[static_cast<size_t>(r)].push_back(c);
      pattern[static_cast<size_t>(c)].push_back(r);
    }
  }
  return pattern;
}

Eigen::Matrix3d random_block(std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::Matrix3d b;
  for (int i = 0; i < 9; ++i) b(i) = value(rng);
  return b;
}

// Writes a random value into every block of the pattern and remembers it, independently of the storage.
BlockMap fill_random(BlockSparseMatrix& matrix, const std::vector<std::vector<int>>& pattern, std::mt19937& rng) {
  BlockMap blocks;
  for (int r = 0; r < static_cast<int>(pattern.size()); ++r) {
    std::vector<int> cols = pattern[static_cast<size_t>(r)];
    cols.push_back(r);
    for (const int c : cols) {
      if (blocks.count({r, c}) != 0) continue;
      const Eigen::Matrix3d b = random_block(rng);
      const int slot = matrix.find_slot(r, c);
      EXPECT_GE(slot, 0) << "block (" << r << ", " << c << ") missing";
      matrix.block(slot) = b;
      blocks[{r, c}] = b;
    }
  }
  return blocks;
}

Eigen::MatrixXd dense_from(const BlockMap& blocks, int block_rows) {
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * block_rows, 3 * block_rows);
  for (const auto& [key, b] : blocks) dense.block<3, 3>(3 * key.first, 3 * key.second) = b;
  return dense;
}

void expect_values(const BlockSparseMatrix& matrix, const BlockMap& blocks) {
  for (const auto& [key, b] : blocks) {
    const int slot = matrix.find_slot(key.first, key.second);
    ASSERT_GE(slot, 0);
    EXPECT_EQ(matrix.block(slot), b) << "block (" << key.first << ", " << key.second << ")";
  }
}

void expect_product_matches(const BlockSparseMatrix& matrix, const BlockMap& blocks, std::mt19937& rng) {
  const Eigen::MatrixXd dense = dense_from(blocks, matrix.block_rows());
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::VectorXd x(matrix.rows());
  for (long i = 0; i < x.size(); ++i) x[i] = value(rng);
  Eigen::VectorXd y;
  matrix.multiply(x, y);
  const Eigen::VectorXd expected = dense * x;
  ASSERT_EQ(y.size(), expected.size());
  EXPECT_LE((y - expected).norm(), 1e-12 * expected.norm());
}

TEST(BlockSparseMatrix, DefaultConstructedIsEmpty) {
  BlockSparseMatrix matrix;
  EXPECT_EQ(matrix.block_rows(), 0);
  EXPECT_EQ(matrix.rows(), 0);
  EXPECT_EQ(matrix.nonzero_blocks(), 0);
  EXPECT_EQ(matrix.find_slot(0, 0), -1);
  Eigen::VectorXd x(0);
  Eigen::VectorXd y(5);
  matrix.multiply(x, y);
  EXPECT_EQ(y.size(), 0);
  // It can still grow: the first append reserves room.
  EXPECT_EQ(matrix.append_block_row(), 0);
  EXPECT_EQ(matrix.rows(), 3);
  EXPECT_GE(matrix.find_slot(0, 0), 0);
  EXPECT_TRUE(matrix.block(matrix.find_slot(0, 0)).isZero());
  // Growing row by row re-lays out geometrically rarely, not once per row.
  for (int k = 1; k < 1000; ++k) EXPECT_EQ(matrix.append_block_row(), k);
  EXPECT_LE(matrix.layout_revision(), 30U);
  EXPECT_EQ(matrix.nonzero_blocks(), 1000);
}

TEST(BlockSparseMatrix, ConstructionMergesDuplicatesAddsDiagonalAndSortsColumns) {
  const std::vector<std::vector<int>> pattern = {{3, 1, 3, 1}, {0}, {}, {0, 2, 2}};
  const BlockSparseMatrix matrix(pattern, {0.5, 2});
  EXPECT_EQ(matrix.block_rows(), 4);
  EXPECT_EQ(matrix.rows(), 12);
  // Rows: {0,1,3}, {0,1}, {2}, {0,2,3}.
  EXPECT_EQ(matrix.nonzero_blocks(), 9);
  EXPECT_EQ(matrix.nonzeros(), 81);
  const std::vector<std::vector<int>> expected = {{0, 1, 3}, {0, 1}, {2}, {0, 2, 3}};
  for (int r = 0; r < 4; ++r) {
    ASSERT_EQ(matrix.row_size(r), static_cast<int>(expected[static_cast<size_t>(r)].size()));
    for (int k = 0; k < matrix.row_size(r); ++k) {
      EXPECT_EQ(matrix.slot_column(matrix.row_begin(r) + k), expected[static_cast<size_t>(r)][static_cast<size_t>(k)]);
    }
  }
  // Reserve: 2 spare rows (ceil(0.5 * 4)); 18 slots for the rows, 2 * ceil(18 / 4) for the spares.
  EXPECT_EQ(matrix.block_row_capacity(), 6);
  EXPECT_EQ(matrix.slot_capacity(), 18 + 2 * 5);
  EXPECT_EQ(matrix.find_slot(2, 0), -1);
  EXPECT_EQ(matrix.find_slot(-1, 0), -1);
  EXPECT_EQ(matrix.find_slot(4, 0), -1);
  // Every used block starts at zero.
  for (int r = 0; r < 4; ++r) {
    for (int k = 0; k < matrix.row_size(r); ++k) EXPECT_TRUE(matrix.block(matrix.row_begin(r) + k).isZero());
  }
}

TEST(BlockSparseMatrix, RejectsColumnsOutsideTheMatrix) {
  EXPECT_THROW(BlockSparseMatrix(Pattern{{0, 2}, {1}}), std::invalid_argument);
  EXPECT_THROW(BlockSparseMatrix(Pattern{{-1}}), std::invalid_argument);
  EXPECT_THROW(BlockSparseMatrix(Pattern{{0}}, {-0.5, 2}), std::invalid_argument);
  EXPECT_THROW(BlockSparseMatrix(Pattern{{0}}, {0.5, 0}), std::invalid_argument);
}

TEST(BlockSparseMatrix, MultiplyMatchesDenseReference) {
  std::mt19937 rng(11);
  for (const int n : {1, 7, 60, 300}) {
    const auto pattern = random_symmetric_pattern(n, 4, rng);
    BlockSparseMatrix matrix(pattern);
    const BlockMap blocks = fill_random(matrix, pattern, rng);
    EXPECT_EQ(matrix.nonzero_blocks(), static_cast<int>(blocks.size()));
    expect_product_matches(matrix, blocks, rng);
  }
}

// Two threads of CG each take one part of the rows: the parts' products together are the whole
// product bitwise, and the split balances the blocks to within one row's.
TEST(BlockSparseMatrix, RowPartsOfTheProductMakeTheWholeAndBalanceTheBlocks) {
  std::mt19937 rng(12);
  for (const int n : {1, 2, 7, 300}) {
    const auto pattern = random_symmetric_pattern(n, 4, rng);
    BlockSparseMatrix matrix(pattern);
    fill_random(matrix, pattern, rng);
    Eigen::VectorXd x(matrix.rows());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
    Eigen::VectorXd whole;
    matrix.multiply(x, whole);
    const int split = matrix.balanced_row_split(1, 2);
    ASSERT_EQ(matrix.balanced_row_split(0, 2), 0);
    ASSERT_EQ(matrix.balanced_row_split(2, 2), n);
    // One part holds every row (set_zero with no team zeroed nothing while this returned 0).
    ASSERT_EQ(matrix.balanced_row_split(1, 1), n);
    ASSERT_GE(split, 0);
    ASSERT_LE(split, n);
    Eigen::VectorXd parts = Eigen::VectorXd::Constant(matrix.rows(), std::numeric_limits<double>::quiet_NaN());
    matrix.multiply_rows(x, parts, split, n);
    matrix.multiply_rows(x, parts, 0, split);
    EXPECT_TRUE(parts == whole) << n << " block rows, split at " << split;
    int blocks_before = 0;
    int widest_row = 0;
    for (int r = 0; r < n; ++r) {
      if (r < split) blocks_before += matrix.row_size(r);
      widest_row = std::max(widest_row, matrix.row_size(r));
    }
    EXPECT_LE(std::abs(2 * blocks_before - matrix.nonzero_blocks()), 2 * widest_row) << n << " block rows";
  }
}

TEST(BlockSparseMatrix, MultiplyRejectsWrongSizeAndAliasing) {
  BlockSparseMatrix matrix(Pattern{{1}, {0}});
  Eigen::VectorXd x = Eigen::VectorXd::Ones(5);
  Eigen::VectorXd y;
  EXPECT_THROW(matrix.multiply(x, y), std::invalid_argument);
  x = Eigen::VectorXd::Ones(6);
  EXPECT_THROW(matrix.multiply(x, x), std::invalid_argument);
}

TEST(BlockSparseMatrix, DiagonalAndSetZero) {
  std::mt19937 rng(3);
  const auto pattern = random_symmetric_pattern(20, 3, rng);
  BlockSparseMatrix matrix(pattern);
  const BlockMap blocks = fill_random(matrix, pattern, rng);
  Eigen::VectorXd diagonal;
  matrix.diagonal(diagonal);
  EXPECT_EQ(diagonal, dense_from(blocks, 20).diagonal());

  const int nonzero_blocks = matrix.nonzero_blocks();
  const auto revision = matrix.pattern_revision();
  matrix.set_zero();
  EXPECT_EQ(matrix.nonzero_blocks(), nonzero_blocks);
  EXPECT_EQ(matrix.pattern_revision(), revision);
  for (const auto& [key, b] : blocks) EXPECT_TRUE(matrix.block(matrix.find_slot(key.first, key.second)).isZero());
  Eigen::VectorXd y;
  matrix.multiply(Eigen::VectorXd::Ones(matrix.rows()), y);
  EXPECT_TRUE(y.isZero(0.0));
}

TEST(BlockSparseMatrix, InsertIntoSpareRoomKeepsSlotsAndValues) {
  std::mt19937 rng(5);
  // A chain: row r couples to r - 1 and r + 1, so there is plenty of absent (r, r + 5).
  const int n = 30;
  std::vector<std::vector<int>> pattern(n);
  for (int r = 0; r + 1 < n; ++r) {
    pattern[static_cast<size_t>(r)].push_back(r + 1);
    pattern[static_cast<size_t>(r) + 1].push_back(r);
  }
  BlockSparseMatrix matrix(pattern, {0.5, 2});
  BlockMap blocks = fill_random(matrix, pattern, rng);
  std::map<std::pair<int, int>, int> slots;
  for (const auto& [key, b] : blocks) slots[key] = matrix.find_slot(key.first, key.second);

  const auto layout = matrix.layout_revision();
  const auto pattern_revision = matrix.pattern_revision();
  const int nonzero_blocks = matrix.nonzero_blocks();

  // Row 5 holds {4, 5, 6} in 6 slots: three more blocks fit.
  const int a = matrix.insert_block(5, 20);
  const int b = matrix.insert_block(5, 0);
  const int c = matrix.insert_block(5, 29);
  EXPECT_EQ(matrix.layout_revision(), layout);
  EXPECT_GT(matrix.pattern_revision(), pattern_revision);
  EXPECT_EQ(matrix.nonzero_blocks(), nonzero_blocks + 3);
  EXPECT_EQ(matrix.find_slot(5, 20), a);
  EXPECT_EQ(matrix.find_slot(5, 0), b);
  EXPECT_EQ(matrix.find_slot(5, 29), c);
  for (const int slot : {a, b, c}) EXPECT_TRUE(matrix.block(slot).isZero());
  // Every slot handed out before is still the slot of the same block, with the same value.
  for (const auto& [key, slot] : slots) {
    EXPECT_EQ(matrix.find_slot(key.first, key.second), slot);
    EXPECT_EQ(matrix.block(slot), blocks[key]);
  }
  // Inserting a block that exists returns its slot and changes nothing.
  const auto revision_after = matrix.pattern_revision();
  EXPECT_EQ(matrix.insert_block(5, 20), a);
  EXPECT_EQ(matrix.insert_block(7, 6), (slots[{7, 6}]));
  EXPECT_EQ(matrix.pattern_revision(), revision_after);

  // Values written into the new slots take part in the product.
  for (const auto& [key, slot] : std::map<std::pair<int, int>, int>{{{5, 20}, a}, {{5, 0}, b}, {{5, 29}, c}}) {
    const Eigen::Matrix3d value = random_block(rng);
    matrix.block(slot) = value;
    blocks[key] = value;
  }
  expect_product_matches(matrix, blocks, rng);
  EXPECT_THROW(matrix.insert_block(5, n), std::out_of_range);
  EXPECT_THROW(matrix.insert_block(-1, 0), std::out_of_range);
}

TEST(BlockSparseMatrix, OverflowRelaysOutAndKeepsValues) {
  std::mt19937 rng(9);
  const auto pattern = random_symmetric_pattern(40, 3, rng);
  BlockSparseMatrix matrix(pattern, {0.5, 1});  // no room at all in the rows
  BlockMap blocks = fill_random(matrix, pattern, rng);
  const auto layout = matrix.layout_revision();
  const auto pattern_revision = matrix.pattern_revision();

  int row = 0;
  int col = 0;
  while (matrix.find_slot(row, col) >= 0) ++col;  // the first absent block of row 0
  const int slot = matrix.insert_block(row, col);
  EXPECT_NE(matrix.layout_revision(), layout);
  EXPECT_NE(matrix.pattern_revision(), pattern_revision);
  EXPECT_EQ(matrix.find_slot(row, col), slot);
  EXPECT_TRUE(matrix.block(slot).isZero());
  expect_values(matrix, blocks);  // looked up again: the slots moved, the values did not change
  const Eigen::Matrix3d value = random_block(rng);
  matrix.block(slot) = value;
  blocks[{row, col}] = value;
  expect_product_matches(matrix, blocks, rng);

  // The re-laid-out row has room now: the next insertion into it does not move anything.
  const auto layout_after = matrix.layout_revision();
  ++col;
  while (matrix.find_slot(row, col) >= 0) ++col;
  matrix.insert_block(row, col);
  EXPECT_EQ(matrix.layout_revision(), layout_after);
  // Re-layout puts each row back in column order.
  for (int k = 1; k < matrix.row_size(1); ++k) {
    EXPECT_LT(matrix.slot_column(matrix.row_begin(1) + k - 1), matrix.slot_column(matrix.row_begin(1) + k));
  }
}

TEST(BlockSparseMatrix, AppendUsesSpareRowsUntilTheyRunOut) {
  std::mt19937 rng(13);
  const int n = 10;
  const auto pattern = random_symmetric_pattern(n, 2, rng);
  BlockSparseMatrix matrix(pattern, {0.5, 2});
  BlockMap blocks = fill_random(matrix, pattern, rng);
  ASSERT_EQ(matrix.block_row_capacity(), 15);
  const auto layout = matrix.layout_revision();
  std::map<std::pair<int, int>, int> slots;
  for (const auto& [key, b] : blocks) slots[key] = matrix.find_slot(key.first, key.second);

  for (int k = 0; k < 5; ++k) {
    const auto pattern_revision = matrix.pattern_revision();
    const int row = matrix.append_block_row();
    EXPECT_EQ(row, n + k);
    EXPECT_EQ(matrix.block_rows(), n + k + 1);
    EXPECT_GT(matrix.pattern_revision(), pattern_revision);
    EXPECT_EQ(matrix.layout_revision(), layout);
    const int diagonal = matrix.find_slot(row, row);
    ASSERT_GE(diagonal, 0);
    EXPECT_TRUE(matrix.block(diagonal).isZero());
    // An enriched row couples to an old row and back; a spare row has room for it.
    const int coupled = k % n;
    const int forward = matrix.insert_block(row, coupled);
    const int backward = matrix.insert_block(coupled, row);
    EXPECT_EQ(matrix.layout_revision(), layout);
    for (const auto& [key, slot] : std::map<std::pair<int, int>, int>{
             {{row, row}, diagonal}, {{row, coupled}, forward}, {{coupled, row}, backward}}) {
      const Eigen::Matrix3d value = random_block(rng);
      matrix.block(slot) = value;
      blocks[key] = value;
      slots[key] = slot;
    }
  }
  for (const auto& [key, slot] : slots) EXPECT_EQ(matrix.find_slot(key.first, key.second), slot);
  expect_product_matches(matrix, blocks, rng);

  // The sixth append finds no spare row: the storage is re-laid out, values kept, new spares reserved.
  const int row = matrix.append_block_row();
  EXPECT_EQ(row, 15);
  EXPECT_NE(matrix.layout_revision(), layout);
  EXPECT_GT(matrix.block_row_capacity(), 16);
  blocks[{row, row}] = Eigen::Matrix3d::Zero();
  expect_values(matrix, blocks);
  expect_product_matches(matrix, blocks, rng);
  const auto layout_after = matrix.layout_revision();
  matrix.append_block_row();
  EXPECT_EQ(matrix.layout_revision(), layout_after);
}

TEST(BlockSparseMatrix, NoSpareRowsMeansAppendRelaysOut) {
  BlockSparseMatrix matrix(Pattern{{1}, {0}}, {0.0, 2});
  EXPECT_EQ(matrix.block_row_capacity(), 2);
  matrix.block(matrix.find_slot(0, 1)) = Eigen::Matrix3d::Identity();
  const auto layout = matrix.layout_revision();
  EXPECT_EQ(matrix.append_block_row(), 2);
  EXPECT_NE(matrix.layout_revision(), layout);
  EXPECT_EQ(matrix.block(matrix.find_slot(0, 1)), Eigen::Matrix3d::Identity());
}

TEST(BlockSparseMatrix, MinimumRowCapacityIsReservedAtConstruction) {
  // Row 0 has 2 blocks (x2 = 4 slots) but asks for 6: four more columns fit without a re-layout.
  BlockSparseMatrix matrix(Pattern{{1}, {0}, {}, {}, {}, {}}, {0.0, 2}, {6, 0, 0, 0, 0, 0});
  const auto layout = matrix.layout_revision();
  for (int c = 2; c < 6; ++c) matrix.insert_block(0, c);
  EXPECT_EQ(matrix.layout_revision(), layout);
  EXPECT_EQ(matrix.row_size(0), 6);
  matrix.insert_block(1, 2);  // row 1 keeps its doubled room: 4 slots for its 2 blocks
  matrix.insert_block(1, 3);
  EXPECT_EQ(matrix.layout_revision(), layout);
  matrix.insert_block(1, 4);
  EXPECT_NE(matrix.layout_revision(), layout);
  EXPECT_THROW(BlockSparseMatrix(Pattern{{1}, {0}}, {}, {3}), std::invalid_argument);
}

TEST(BlockSparseMatrix, AppendedRowTakesItsRoomFromTheSparePool) {
  // 8 rows of 2 blocks: 4 slots per row, 4 spare rows of 4 slots = a pool of 16 slots.
  std::mt19937 rng(5);
  Pattern pattern(8);
  for (int r = 0; r < 8; ++r) pattern[static_cast<size_t>(r)] = {(r + 1) % 8};
  BlockSparseMatrix matrix(pattern, {0.5, 2});
  BlockMap blocks = fill_random(matrix, pattern, rng);
  const auto layout = matrix.layout_revision();
  const int wide = matrix.append_block_row(10);  // a row of high valence: 10 of the 16 slots
  for (int c = 0; c < 8; ++c) {
    matrix.block(matrix.insert_block(wide, c)) = Eigen::Matrix3d::Identity() * c;
    blocks[{wide, c}] = Eigen::Matrix3d::Identity() * c;
  }
  blocks[{wide, wide}] = Eigen::Matrix3d::Zero();
  EXPECT_EQ(matrix.layout_revision(), layout);  // 9 blocks in 10 slots, all in place
  matrix.append_block_row();                    // the remaining 6 slots hold one more row of 4
  EXPECT_EQ(matrix.layout_revision(), layout);
  blocks[{9, 9}] = Eigen::Matrix3d::Zero();
  matrix.append_block_row();  // 2 slots left: the pool is empty before the spare rows are
  EXPECT_NE(matrix.layout_revision(), layout);
  blocks[{10, 10}] = Eigen::Matrix3d::Zero();
  expect_values(matrix, blocks);
  expect_product_matches(matrix, blocks, rng);
  const auto layout_after = matrix.layout_revision();
  matrix.append_block_row(40);  // wider than a fresh batch of spare rows: the batch grows to fit it
  matrix.append_block_row();
  EXPECT_EQ(matrix.layout_revision(), layout_after + 1);
}

// reserve_room re-lays the rows out in place (no second buffer): rows in the middle that grow push
// the later ones past where the earlier ones lay, blocks appended out of column order come back in
// order, every value and the slot map survive, and every slot no block uses is clear (-1, zero), as
// insert_block and the product rely on.
// The storage has twice the initial slots from the start: the re-layouts of a cutting session stay in
// it (in a real-time session, pages the host locked at its start) instead of moving the values into
// fresh pages within a step (the coarse organ's first re-layout: 2.9 ms of its 3.4). Before, the
// storage was exactly the initial slots and the first growth moved it.
TEST(BlockSparseMatrix, ReLayoutsWithinTwiceTheInitialSlotsKeepTheStorage) {
  std::mt19937 rng(23);
  const Pattern pattern = random_symmetric_pattern(200, 3, rng);
  BlockSparseMatrix matrix(pattern, {0.0, 1});  // compact rows, no spare rows
  BlockMap blocks = fill_random(matrix, pattern, rng);
  const int capacity_before = matrix.slot_capacity();
  const double* storage = matrix.block(0).data();
  // Three cuts' worth: rows 0 .. 59, 20 at a time, each need 4 blocks more than they hold (their
  // room doubles): ~30% more slots in all.
  for (int first = 0; first < 60; first += 20) {
    std::vector<std::pair<int, int>> extra;
    for (int r = first; r < first + 20; ++r) extra.emplace_back(r, 4);
    ASSERT_TRUE(matrix.reserve_room(extra));
    EXPECT_EQ(matrix.block(0).data(), storage) << "the values moved to new storage";
  }
  ASSERT_GT(matrix.slot_capacity(), capacity_before + capacity_before / 4);
  ASSERT_LT(matrix.slot_capacity(), 2 * capacity_before);
  expect_values(matrix, blocks);
  expect_product_matches(matrix, blocks, rng);
}

TEST(BlockSparseMatrix, HeldStorageIsResidentFromTheStart) {
  // The storage held for re-layouts (twice the slots) is written at the start, so a cut step's
  // re-layout does not fault its pages in (a host without mlockall: Python, an FMU importer). The
  // values here are ~3 MB, allocated by mmap: untouched pages would not be resident.
  std::mt19937 rng(29);
  const Pattern pattern = random_symmetric_pattern(3000, 3, rng);
  const BlockSparseMatrix matrix(pattern, {0.0, 1});
  ASSERT_GE(matrix.held_slots(), 2 * matrix.slot_capacity() - 1);
  const long page = sysconf(_SC_PAGESIZE);
  const auto first = reinterpret_cast<std::uintptr_t>(matrix.block(0).data()) / static_cast<std::uintptr_t>(page);
  const auto last = (reinterpret_cast<std::uintptr_t>(matrix.block(0).data() + 9L * matrix.held_slots()) - 1) /
                    static_cast<std::uintptr_t>(page);
  std::vector<unsigned char> resident(last - first + 1);
  ASSERT_EQ(mincore(reinterpret_cast<void*>(first * static_cast<std::uintptr_t>(page)),
                    (last - first + 1) * static_cast<std::uintptr_t>(page), resident.data()),
            0);
  const auto missing = std::count_if(resident.begin(), resident.end(), [](unsigned char r) { return (r & 1) == 0; });
  EXPECT_EQ(missing, 0) << "of " << resident.size() << " pages";
}

TEST(BlockSparseMatrix, ReservingRoomInPlaceKeepsEveryBlockAndClearsTheRest) {
  std::mt19937 rng(17);
  const Pattern pattern = random_symmetric_pattern(30, 2, rng);
  BlockSparseMatrix matrix(pattern, {0.5, 1});  // compact rows
  BlockMap blocks = fill_random(matrix, pattern, rng);
  std::uniform_int_distribution<int> pick(0, 29);
  for (int round = 0; round < 6; ++round) {
    // A few rows (the first, the last, some between) gain blocks beyond their room; first the room.
    std::vector<std::pair<int, int>> extra{{0, 3}, {29, 2}, {pick(rng), 12}, {pick(rng), 5}};
    std::map<int, int> slot_of_block_before;  // old slot -> (row * 30 + column)
    for (const auto& [key, value] : blocks) slot_of_block_before[matrix.find_slot(key.first, key.second)] = key.first * 30 + key.second;
    const int capacity_before = matrix.slot_capacity();
    const auto layout = matrix.layout_revision();
    const bool moved = matrix.reserve_room(extra);
    ASSERT_TRUE(moved);
    EXPECT_EQ(matrix.layout_revision(), layout + 1);
    const std::vector<int>& map = matrix.relayout_slot_map();
    ASSERT_EQ(static_cast<int>(map.size()), capacity_before);
    for (const auto& [old_slot, key] : slot_of_block_before) {
      EXPECT_EQ(map[static_cast<size_t>(old_slot)], matrix.find_slot(key / 30, key % 30));
    }
    for (int r = 0; r < matrix.block_rows(); ++r) {  // each row back in column order
      for (int k = 1; k < matrix.row_size(r); ++k) {
        EXPECT_LT(matrix.slot_column(matrix.row_begin(r) + k - 1), matrix.slot_column(matrix.row_begin(r) + k));
      }
    }
    // Then the blocks, in descending column order (the room holds them: nothing moves).
    for (const auto& [row, count] : extra) {
      for (int c = 29, added = 0; c >= 0 && added < count; --c) {
        if (matrix.find_slot(row, c) >= 0) continue;
        const Eigen::Matrix3d value = random_block(rng);
        matrix.block(matrix.insert_block(row, c)) = value;
        blocks[{row, c}] = value;
        ++added;
      }
    }
    EXPECT_EQ(matrix.layout_revision(), layout + 1);
    expect_values(matrix, blocks);
    expect_product_matches(matrix, blocks, rng);
    int used = 0;
    for (int r = 0; r < matrix.block_rows(); ++r) used += matrix.row_size(r);
    int clear = 0;
    for (int slot = 0; slot < matrix.slot_capacity(); ++slot) {
      if (matrix.slot_column(slot) >= 0) continue;
      ++clear;
      EXPECT_TRUE(matrix.block(slot).isZero()) << "slot " << slot << " of round " << round;
    }
    EXPECT_EQ(used + clear, matrix.slot_capacity());
  }
}

// A view of another matrix's rows (view_rows_of, CompactRowsSolver's system) reads that matrix's
// values: the mutators that would write values it does not hold refuse, and the viewed matrix keeps
// its blocks.
TEST(BlockSparseMatrix, AViewRefusesToChangeItsValuesOrPattern) {
  std::mt19937 rng(29);
  const Pattern pattern = random_symmetric_pattern(12, 2, rng);
  BlockSparseMatrix matrix(pattern, {0.5, 1});
  const BlockMap blocks = fill_random(matrix, pattern, rng);
  std::vector<int> rows(12);
  std::vector<int> index_of_row(12);
  for (int r = 0; r < 12; ++r) rows[static_cast<size_t>(r)] = index_of_row[static_cast<size_t>(r)] = r;
  BlockSparseMatrix view;
  view.view_rows_of(matrix, rows, index_of_row);
  EXPECT_THROW(view.set_zero(), std::logic_error);
  EXPECT_THROW(view.insert_block(0, 11), std::logic_error);
  EXPECT_THROW(view.append_block_row(), std::logic_error);
  EXPECT_THROW(view.reserve_room({{0, 4}}), std::logic_error);
  EXPECT_THROW(view.remove_blocks(std::vector<std::uint8_t>(static_cast<size_t>(view.slot_capacity()), 1)),
               std::logic_error);
  expect_values(matrix, blocks);
  expect_product_matches(view, blocks, rng);
}

// Removing blocks with the rows packed (issue 41, item 3: the room cuts left in the rows): rows that
// had grown room (and appended rows with their own) move back to back with room for just their
// blocks, each keeping its blocks in their order (the product's sums in the same order), the
// slot map says where every kept block went, the freed slots are unused and zero, and the matrix then
// grows again (a block inserted into a packed row re-lays it out) as before.
TEST(BlockSparseMatrix, RemovingBlocksWithTheRowsPackedKeepsOrderValuesAndProduct) {
  std::mt19937 rng(23);
  const Pattern pattern = random_symmetric_pattern(40, 2, rng);
  BlockSparseMatrix matrix(pattern, {0.5, 1});
  BlockMap blocks = fill_random(matrix, pattern, rng);
  std::uniform_int_distribution<int> pick(0, 39);
  ASSERT_TRUE(matrix.reserve_room({{0, 20}, {39, 9}, {pick(rng), 30}, {pick(rng), 14}}));
  for (int k = 0; k < 3; ++k) {  // rows appended (XFEM's ghosts), with blocks to the first rows
    const int row = matrix.append_block_row(24);
    for (const int c : {k, 2 * k + 1}) {
      for (const auto& [r, col] : {std::pair{row, c}, std::pair{c, row}}) {
        const Eigen::Matrix3d value = random_block(rng);
        matrix.block(matrix.insert_block(r, col)) = value;
        blocks[{r, col}] = value;
      }
    }
    blocks[{row, row}] = matrix.block(matrix.diagonal_slot(row));
  }
  // Every fourth off-diagonal block goes.
  std::vector<std::uint8_t> keep(static_cast<size_t>(matrix.slot_capacity()), 1);
  std::map<int, std::pair<int, int>> kept_at;  // old slot -> block
  std::vector<std::vector<int>> order_before(static_cast<size_t>(matrix.block_rows()));
  int counted = 0;
  for (int r = 0; r < matrix.block_rows(); ++r) {
    for (int slot = matrix.row_begin(r); slot < matrix.row_begin(r) + matrix.row_size(r); ++slot) {
      const int column = matrix.slot_column(slot);
      if (column != r && ++counted % 4 == 0) {
        keep[static_cast<size_t>(slot)] = 0;
        blocks.erase({r, column});
        continue;
      }
      kept_at[slot] = {r, column};
      order_before[static_cast<size_t>(r)].push_back(column);
    }
  }
  ASSERT_GT(matrix.row_room(), matrix.nonzero_blocks() + 50);  // room to give back
  Eigen::VectorXd x = Eigen::VectorXd::Random(matrix.rows());
  const auto layout = matrix.layout_revision();
  const int slots_before = matrix.slot_capacity();
  ASSERT_TRUE(matrix.remove_blocks(keep, BlockSparseMatrix::RowRoom::packed));
  EXPECT_EQ(matrix.layout_revision(), layout + 1);
  EXPECT_EQ(matrix.row_room(), matrix.nonzero_blocks());
  EXPECT_LT(matrix.slot_capacity(), slots_before);
  const std::vector<int>& map = matrix.relayout_slot_map();
  for (const auto& [old_slot, block] : kept_at) {
    EXPECT_EQ(map[static_cast<size_t>(old_slot)], matrix.find_slot(block.first, block.second));
  }
  for (int r = 0; r < matrix.block_rows(); ++r) {
    EXPECT_EQ(matrix.row_capacity(r), matrix.row_size(r));
    if (r > 0) {
      EXPECT_EQ(matrix.row_begin(r), matrix.row_begin(r - 1) + matrix.row_size(r - 1));
    }
    std::vector<int> order;
    for (int slot = matrix.row_begin(r); slot < matrix.row_begin(r) + matrix.row_size(r); ++slot) {
      order.push_back(matrix.slot_column(slot));
    }
    EXPECT_EQ(order, order_before[static_cast<size_t>(r)]) << "row " << r;
    EXPECT_EQ(matrix.slot_column(matrix.diagonal_slot(r)), r);
  }
  expect_values(matrix, blocks);
  expect_product_matches(matrix, blocks, rng);
  for (int slot = matrix.row_room(); slot < matrix.slot_capacity(); ++slot) {
    EXPECT_EQ(matrix.slot_column(slot), -1);
    EXPECT_TRUE(matrix.block(slot).isZero()) << "slot " << slot;
  }
  // Nothing to remove and nothing to pack: unchanged.
  EXPECT_FALSE(matrix.remove_blocks(std::vector<std::uint8_t>(static_cast<size_t>(matrix.slot_capacity()), 1),
                                    BlockSparseMatrix::RowRoom::packed));
  // Growth as before: a block into a packed row, a row appended.
  const Eigen::Matrix3d value = random_block(rng);
  int column = 0;
  while (matrix.find_slot(5, column) >= 0) ++column;
  matrix.block(matrix.insert_block(5, column)) = value;
  blocks[{5, column}] = value;
  const int row = matrix.append_block_row();
  blocks[{row, row}] = Eigen::Matrix3d::Zero();
  expect_values(matrix, blocks);
  expect_product_matches(matrix, blocks, rng);
}

}  // namespace
}  // namespace tissue
