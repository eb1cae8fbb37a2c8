// BlockSparseMatrix: a square sparse matrix of 3x3 blocks, stored by block rows, with room
// reserved ahead for the XFEM growth of issue 3 (spare block rows, spare slots per row).
// Values live in "slots" (9 doubles each, column-major 3x3); assembly writes through slot
// indices computed once (see assembly.hpp), so a normal step never searches or allocates.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <utility>
#include <vector>

namespace tissue {

class WorkTeam;

/// Room reserved ahead for growth. The dissertation reserves 150% DOFs and doubles every row's
/// capacity; spare rows cost nothing in a step (they follow the last row), but room inside the rows
/// spreads a step's blocks over more memory: on the 52k-tet organ, rows with room for XFEM's ghosts
/// made a step 25% slower (docs/BENCHMARKS.md, issue 23). So rows start compact and a cut makes room
/// for the rows it grows, all at once (reserve_room), doubling them.
struct MatrixReserve {
  double extra_row_fraction = 0.5;  ///< spare block rows, as a fraction of the initial rows (150% DOFs)
  int row_capacity_factor = 1;      ///< each row gets room for this many times its initial blocks
  int spare_row_capacity = 0;       ///< slots per spare row; 0: the mean initial row's capacity
};

class BlockSparseMatrix {
 public:
  using Reserve = MatrixReserve;

  BlockSparseMatrix() = default;
  /// `pattern[r]` lists the block columns present in block row r (any order, no duplicates needed;
  /// duplicates are merged). The diagonal block of every row is always added. Row r gets room for
  /// max(its blocks * reserve.row_capacity_factor, min_row_capacity[r]) blocks (the second term
  /// only when min_row_capacity is given: one entry per row).
  explicit BlockSparseMatrix(const std::vector<std::vector<int>>& pattern, Reserve reserve = {},
                             const std::vector<int>& min_row_capacity = {});

  [[nodiscard]] int block_rows() const { return static_cast<int>(m_row_begin.size()); }
  [[nodiscard]] int rows() const { return 3 * block_rows(); }
  [[nodiscard]] int nonzero_blocks() const { return m_nonzero_blocks; }
  [[nodiscard]] long nonzeros() const { return 9L * m_nonzero_blocks; }

  /// Slot of block (row, col), or -1 if absent. Searches: for set-up code, not for a step.
  [[nodiscard]] int find_slot(int row, int col) const;
  /// Slot of the diagonal block of `row` (always present). No search.
  [[nodiscard]] int diagonal_slot(int row) const { return m_diagonal_slot[static_cast<size_t>(row)]; }

  [[nodiscard]] Eigen::Map<Eigen::Matrix3d> block(int slot) {
    return Eigen::Map<Eigen::Matrix3d>(&m_values[9 * static_cast<size_t>(slot)]);
  }
  [[nodiscard]] Eigen::Map<const Eigen::Matrix3d> block(int slot) const {
    return Eigen::Map<const Eigen::Matrix3d>(values() + 9 * static_cast<size_t>(slot));
  }

  /// Adds b (add_block) or b^T (add_block_transposed) to the block in `slot`, entry by entry in
  /// storage order. An assembly adds to each block once per element that shares it, and these two
  /// always load and store its nine values the same way, so one element's loads take the last
  /// one's stores from the store buffer: Eigen's `+= b` and `+= b.transpose()` split the values
  /// differently, and a load spanning two earlier stores waits for them to reach the cache (the
  /// frog's forces and tangent ~11% faster; docs/BENCHMARKS.md, issue 40). The co-rotational
  /// kernel adds its blocks in lanes, always the same way too (corotational.cpp).
  void add_block(int slot, const Eigen::Matrix3d& b) {
    double* __restrict to = &m_values[9 * static_cast<size_t>(slot)];
    const double* __restrict from = b.data();
    for (int k = 0; k < 9; ++k) to[k] += from[k];
  }
  void add_block_transposed(int slot, const Eigen::Matrix3d& b) {
    double* __restrict to = &m_values[9 * static_cast<size_t>(slot)];
    for (int column = 0; column < 3; ++column) {
      for (int row = 0; row < 3; ++row) to[3 * column + row] += b(column, row);
    }
  }

  /// Zeroes all values (pattern kept).
  void set_zero();
  /// The same, the rows shared among `team`'s members (nullptr: this thread).
  void set_zero(WorkTeam* team);

  /// y = A x, both of length rows(). y is overwritten. No allocation.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// The same, the rows shared among `team`'s members (nullptr: this thread); bitwise the same.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, WorkTeam* team) const;
  /// The block rows [first_block_row, end_block_row) of y = A x; y must have length rows() already
  /// (two threads may fill disjoint row ranges of one y). Sizes are the caller's to check.
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first_block_row, int end_block_row) const;
  /// The first block row of part `part` of `parts` consecutive row ranges holding about equal
  /// numbers of blocks (part 0 starts at row 0).
  [[nodiscard]] int balanced_row_split(int part, int parts) const;

  /// The scalar diagonal (length rows()) into `diagonal` (resized if needed).
  void diagonal(Eigen::VectorXd& diagonal) const;

  // --- Iteration over the pattern (for conversions such as CHOLMOD) ---
  [[nodiscard]] int row_begin(int row) const { return m_row_begin[static_cast<size_t>(row)]; }
  [[nodiscard]] int row_size(int row) const { return m_row_size[static_cast<size_t>(row)]; }
  /// Blocks the row has room for before it must be re-laid out.
  [[nodiscard]] int row_capacity(int row) const { return m_row_capacity[static_cast<size_t>(row)]; }
  /// Block column of a slot.
  [[nodiscard]] int slot_column(int slot) const { return m_column[static_cast<size_t>(slot)]; }

  // --- Growth (XFEM) ---
  /// Appends an empty block row (with its diagonal block) and returns its index. The row gets room
  /// for max(min_capacity, the spare-row capacity) blocks, taken from the spare room after the last
  /// row when it suffices; otherwise the storage is re-laid out (see layout_revision()). A caller
  /// that knows how many blocks the row can ever hold (XFEM: twice the vertex's neighbourhood)
  /// passes it, so that rows of high valence do not overflow later.
  int append_block_row(int min_capacity = 0);
  /// Returns the slot of block (row, col), inserting it into the spare room of `row` if absent.
  /// New blocks are zero. When the row has no room left, the storage is re-laid out and
  /// layout_revision() changes: every slot index held elsewhere must then be looked up again.
  int insert_block(int row, int col);
  /// Makes room for `extra` more blocks in each listed row (row, extra): rows that lack it get what
  /// they need, at least twice their blocks, in one re-layout (none when every row has the room).
  /// Pairs need not be unique (a row's extras add up). Returns whether the storage was re-laid out.
  bool reserve_room(const std::vector<std::pair<int, int>>& row_extra);
  /// What remove_blocks leaves of the rows' room.
  enum class RowRoom {
    kept,   ///< each row closes up in place and keeps its room
    packed  ///< the rows move back to back, each with room for just its blocks
  };
  /// Removes the blocks whose slot is not marked in `keep` (one entry per slot, slot_capacity();
  /// the diagonal blocks stay whatever it says), each row's blocks closing up in their order.
  /// Returns whether a block went or (packed) a row moved or lost room; then the layout changed
  /// (layout_revision(), pattern_revision()) and relayout_slot_map() tells where the kept slots
  /// went. For the XFEM's blocks that only retired cut tets used (zeros the product would multiply
  /// every step); packed, for the room cuts left in the rows (row_room()), which spreads every pass
  /// over the blocks (zeroing, assembly, products) over memory it mostly does not use. Neither
  /// changes a kept block's value or a row's blocks' order: packing alone leaves every product
  /// bitwise as it was.
  bool remove_blocks(const std::vector<std::uint8_t>& keep, RowRoom room = RowRoom::kept);
  /// The slots the rows take with their room, where the spare rows' room begins: nonzero_blocks()
  /// when packed.
  [[nodiscard]] int row_room() const;
  /// After a re-layout: the new slot of each old slot (-1: an unused one), until the next re-layout.
  [[nodiscard]] const std::vector<int>& relayout_slot_map() const { return m_relayout_slot_map; }

  /// Makes this matrix a view of the block rows `rows` of `k` (ascending), renumbered 0, 1, ... in
  /// that order, each in the slots it has in k: `index_of_row[r]` is k's row r's number here, or -1
  /// for a row left out, with which no row kept may have a block (throws std::invalid_argument). Its
  /// values are k's, read where k keeps them (no copy): it is read only (block() const, products),
  /// valid while k's layout stays as it is and k lives. Both revisions move on: nothing made of this
  /// matrix's earlier pattern is taken for this one (core/solve/compact_rows_solver.hpp). Its
  /// mutators that are not per block (set_zero, insert_block, append_block_row, reserve_room,
  /// remove_blocks) throw std::logic_error on a view; block(slot) and add_block are not checked (a
  /// step's inner loops): writing through them is the caller's error.
  void view_rows_of(const BlockSparseMatrix& k, const std::vector<int>& rows, const std::vector<int>& index_of_row);

  /// Changes whenever the set of blocks changes (append_block_row, insert_block of a new block).
  [[nodiscard]] std::uint64_t pattern_revision() const { return m_pattern_revision; }
  /// Changes only when existing slots moved (storage re-laid out: a row outgrew its room, or the
  /// spare rows ran out).
  [[nodiscard]] std::uint64_t layout_revision() const { return m_layout_revision; }
  /// Reserved capacity, in block rows and in slots.
  [[nodiscard]] int block_row_capacity() const { return m_block_row_capacity; }
  [[nodiscard]] int slot_capacity() const { return static_cast<int>(m_column.size()); }
  /// Slots the storage holds before it must move (reserve_slots), its pages touched.
  [[nodiscard]] int held_slots() const { return static_cast<int>(m_column.capacity()); }

 private:
  /// Rebuilds the storage with room to spare: every row keeps at least its capacity (and
  /// row_size * row_capacity_factor), `grow_row` (or -1) at least doubles, and `spare_rows`
  /// empty rows of m_spare_row_capacity slots follow the last row. Rows come out sorted.
  /// `min_capacity` (row, capacity): rows that get at least that much.
  void relayout(const std::vector<std::pair<int, int>>& min_capacity, int spare_rows);
  /// Storage for at least `slots` slots, twice that whenever it must grow (from the start too): a
  /// re-layout (a cut's rows outgrowing their room) then stays in the storage it has, whose pages a
  /// real-time host locked at its start, instead of moving megabytes into fresh pages within a step
  /// (resect_lobe's re-layouts grow the coarse organ's slots 56k -> 68k -> 75k; moving them took
  /// 2.9 ms of a 3.4 ms re-layout). The held storage is written once here, so that its pages are
  /// resident before a step needs them: a host that does not lock its memory (Python, an FMU
  /// importer) otherwise took a fault per page in the cut step whose re-layout first wrote it
  /// (the frog: 1.3-2.0 ms of a re-layout, 0.2-0.7 ms without).
  void reserve_slots(size_t slots);
  /// Throws std::logic_error when this matrix is a view (view_rows_of), whose values are another's.
  void refuse_on_a_view(const char* operation) const;

  std::vector<int> m_row_begin;      // first slot of each block row
  std::vector<int> m_row_size;       // blocks in use in each row
  std::vector<int> m_row_capacity;   // slots reserved for each row
  std::vector<int> m_column;         // block column of each slot (-1 = unused)
  std::vector<double> m_values;      // 9 per slot, column-major 3x3 (none in a view)
  const BlockSparseMatrix* m_viewed = nullptr;  // view_rows_of's k, whose values this one reads
  [[nodiscard]] const double* values() const {
    return m_viewed != nullptr ? m_viewed->m_values.data() : m_values.data();
  }
  std::vector<int> m_diagonal_slot;  // slot of the diagonal block of each row (always present)
  std::vector<int> m_relayout_slot_map;  // old slot -> new slot of the last re-layout
  int m_nonzero_blocks = 0;
  int m_spare_row_capacity = 0;  // slots reserved per spare row (appended rows take at least this)
  int m_block_row_capacity = 0;
  Reserve m_reserve;
  std::uint64_t m_pattern_revision = 0;
  std::uint64_t m_layout_revision = 0;
};

}  // namespace tissue
