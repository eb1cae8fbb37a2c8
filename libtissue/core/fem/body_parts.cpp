// The parts a cut body has fallen into (see body_parts.hpp).
#include "core/fem/body_parts.hpp"

#include "core/fem/deformable_body.hpp"
#include "core/fem/union_find.hpp"

#include <array>
#include <numeric>

namespace tissue {
namespace {

// A union-find over the block rows plus one entry for the fixed vertices (row -1), which stays a
// root: every part joined to it is held.
class RowUnion {
 public:
  explicit RowUnion(int rows) : m_parent(static_cast<size_t>(rows) + 1), m_held(rows) {
    std::iota(m_parent.begin(), m_parent.end(), 0);
  }
  [[nodiscard]] int held_root() const { return m_held; }
  int root(int i) { return find_root(m_parent, i < 0 ? m_held : i); }
  void join(const std::array<int, 4>& rows) {
    for (size_t j = 1; j < 4; ++j) unite(rows[0], rows[j]);
  }

 private:
  void unite(int a, int b) {
    const int root_a = root(a);
    const int root_b = root(b);
    if (root_a == root_b) return;
    if (root_a == m_held) m_parent[static_cast<size_t>(root_b)] = root_a;
    else m_parent[static_cast<size_t>(root_a)] = root_b;
  }
  std::vector<int> m_parent;
  int m_held;
};

}  // namespace

BodyParts find_body_parts(const DeformableBody& body) {
  const int rows = body.dof_count() / 3;
  const TetMesh& mesh = body.mesh();
  const std::vector<int>& vertex_row = body.dofs().vertex_row;
  RowUnion parts(rows);
  std::vector<std::uint8_t> used(static_cast<size_t>(rows), 0);
  const auto join = [&](const std::array<int, 4>& element_rows) {
    for (const int row : element_rows) {
      if (row >= 0) used[static_cast<size_t>(row)] = 1;
    }
    parts.join(element_rows);
  };
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (body.cut_tet_index(t) >= 0) continue;
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    join({vertex_row[static_cast<size_t>(tet[0])], vertex_row[static_cast<size_t>(tet[1])],
          vertex_row[static_cast<size_t>(tet[2])], vertex_row[static_cast<size_t>(tet[3])]});
  }
  const XfemElasticity& xfem = body.xfem();
  for (int k = 0; k < xfem.cut_tet_count(); ++k) {
    if (xfem.retired(k)) continue;
    for (int p = 0; p < static_cast<int>(xfem.piece_count(k)); ++p) join(body.piece_rows(k, p));
  }
  BodyParts result;
  result.part_of_row.assign(static_cast<size_t>(rows), -1);
  std::vector<int> part_of_root(static_cast<size_t>(rows) + 1, -1);
  const int held = parts.held_root();
  for (int row = 0; row < rows; ++row) {
    if (!used[static_cast<size_t>(row)]) continue;
    const int root = parts.root(row);
    int& part = part_of_root[static_cast<size_t>(root)];
    if (part < 0) {
      part = result.count();
      result.held.push_back(root == held ? 1 : 0);
    }
    result.part_of_row[static_cast<size_t>(row)] = part;
  }
  return result;
}

}  // namespace tissue
