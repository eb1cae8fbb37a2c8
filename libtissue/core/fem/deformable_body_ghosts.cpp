// Which ghost each piece of a cut tet uses (DeformableBody::enrich, the virtual-node algorithm's node
// copies, Molino et al. 2004): around each vertex, the pieces that the same cuts separate from it and
// that touch across faces share one.
#include "core/fem/deformable_body.hpp"
#include "core/fem/union_find.hpp"

#include "core/fem/deformable_body_enrich.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <utility>
#include <vector>

namespace tissue {
namespace {

// The cuts of `geometry` that separate piece q from its local vertex j, as (cut id, H of the
// vertex) sorted by cut id; none when j lies in the piece.
SeparatingCuts separating_cuts(const CutTetGeometry& geometry, size_t q, size_t j) {
  SeparatingCuts separated;
  const PieceSides& sides = geometry.pieces[q].sides;
  for (size_t k = 0; k < geometry.cuts.size(); ++k) {
    const int vertex_side = geometry.cuts[k].side[j];
    if ((vertex_side > 0) == ((sides.above & (1u << k)) != 0)) continue;
    const auto n = static_cast<size_t>(separated.count++);
    separated.cut_id[n] = geometry.cuts[k].cut_id;
    separated.side[n] = static_cast<std::int8_t>(vertex_side);
  }
  for (int a = 1; a < separated.count; ++a) {  // insertion sort of at most MAX_PIECE_CUTS pairs
    for (int b = a; b > 0 && separated.cut_id[static_cast<size_t>(b)] < separated.cut_id[static_cast<size_t>(b - 1)];
         --b) {
      std::swap(separated.cut_id[static_cast<size_t>(b)], separated.cut_id[static_cast<size_t>(b - 1)]);
      std::swap(separated.side[static_cast<size_t>(b)], separated.side[static_cast<size_t>(b - 1)]);
    }
  }
  return separated;
}

// Twice the area of the part of the triangle `face` (rest positions) that lies in piece q of a tet
// and in piece r of another: the triangle clipped by the planes (CutTetGeometry::planes) that bound
// either piece, each on its piece's side. No allocation: a triangle clipped by up to 2
// MAX_PIECE_CUTS planes has at most 3 + 2 MAX_PIECE_CUTS corners.
double shared_face_area(const std::array<Eigen::Vector3d, 3>& face, const CutTetGeometry& first, size_t q,
                        const CutTetGeometry& second, size_t r) {
  constexpr size_t CAPACITY = 3 + 2 * MAX_PIECE_CUTS + 1;
  std::array<Eigen::Vector3d, CAPACITY> polygon{face[0], face[1], face[2]};
  std::array<Eigen::Vector3d, CAPACITY> kept;
  size_t corners = 3;
  const auto clip = [&](const CutPlane& plane, bool above) {
    size_t count = 0;
    const double sign = above ? 1.0 : -1.0;
    for (size_t i = 0; i < corners; ++i) {
      const Eigen::Vector3d& a = polygon[i];
      const Eigen::Vector3d& b = polygon[(i + 1) % corners];
      const double da = sign * plane.signed_distance(a);
      const double db = sign * plane.signed_distance(b);
      if (da >= 0.0 && count < CAPACITY) kept[count++] = a;
      if (((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) && count < CAPACITY)
        kept[count++] = a + (b - a) * (da / (da - db));
    }
    std::copy(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(count), polygon.begin());
    corners = count;
  };
  for (const auto& [geometry, piece] : {std::pair{&first, q}, std::pair{&second, r}}) {
    const PieceSides& sides = geometry->pieces[piece].sides;
    for (size_t k = 0; k < geometry->cuts.size() && corners >= 3; ++k) {
      if ((sides.bounded & (1u << k)) == 0) continue;
      clip(geometry->planes[k], (sides.above & (1u << k)) != 0);
    }
  }
  if (corners < 3) return 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < corners; ++i) normal += polygon[i].cross(polygon[(i + 1) % corners]);
  return normal.norm();
}

}  // namespace

// The ghosts of `v` for the pieces around it: which existing row each uses, or which new one.
void DeformableBody::plan_ghosts(int v, EnrichBatch& batch) const {
  const std::vector<EnrichBatch::Node>& nodes = batch.nodes;
  batch.nodes.clear();
  const auto star_begin = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v)]);
  const auto star =
      std::span(m_adjacency.vertex_tets)
          .subspan(star_begin,
                   static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v) + 1]) - star_begin);
  collect_star_nodes(v, star, batch);
  // Components, key by key: pieces of the key and the uncut tets of the star (whose material is
  // whole), joined where two of them share a face with material of both on it.
  collect_star_faces(star, batch);
  std::vector<bool> done(nodes.size(), false);
  batch.elements.resize(star.size());
  for (size_t first = 0; first < nodes.size(); ++first) {
    if (done[first]) continue;
    std::vector<size_t> members;  // the nodes of this key; elements n, n + 1, ... are the uncut tets
    for (size_t i = first; i < nodes.size(); ++i) {
      if (nodes[i].key == nodes[first].key) members.push_back(i);
    }
    for (const size_t i : members) done[i] = true;
    join_star_pieces(star, members, batch);
    assign_ghost_rows(v, star, members, batch);
  }
}

// The pieces of the tets around `v` (its star) that cuts separate from it, with their keys and the
// rows they use now.
void DeformableBody::collect_star_nodes(int v, std::span<const int> star, EnrichBatch& batch) const {
  const std::vector<EnrichBatch::Plan>& plans = batch.plans;
  const std::vector<int>& plan_of_tet = batch.plan_of_tet;
  for (const int t : star) {
    const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
    const auto local = static_cast<size_t>(std::find(tet.begin(), tet.end(), v) - tet.begin());
    const int p = plan_of_tet[static_cast<size_t>(t)];
    const int k = cut_tet_index(t);
    if (p < 0 && k < 0) continue;  // uncut: v is real there
    const CutTetGeometry& geometry =
        p >= 0 ? plans[static_cast<size_t>(p)].geometry : m_cut_geometry[static_cast<size_t>(k)];
    for (size_t q = 0; q < geometry.pieces.size(); ++q) {
      const SeparatingCuts key = separating_cuts(geometry, q, local);
      if (key.count == 0) continue;
      int candidate = -1;
      if (p < 0) {
        candidate = m_xfem.piece(k, static_cast<int>(q)).ghost_row[local];
      } else if (const EnrichBatch::Plan& plan = plans[static_cast<size_t>(p)]; plan.from_cut && plan.old >= 0) {
        candidate = m_xfem.piece(plan.old, geometry.pieces[q].parent).ghost_row[local];
      } else if (!plan.from_cut) {
        candidate = plan.rows[q][local];
      }
      // None (-1, or a row new in this batch), or a ghost or held copy behind other cuts: none.
      if ((candidate < 0 && !is_held_copy(candidate)) || !(planned_copy_cuts(candidate, batch) == key)) candidate = -1;
      batch.nodes.push_back(EnrichBatch::Node{t, q, local, key, candidate});
    }
  }
}

// The faces the star's tets share.
void DeformableBody::collect_star_faces(std::span<const int> star, EnrichBatch& batch) const {
  batch.faces.clear();
  for (size_t a = 0; a < star.size(); ++a) {
    const int t = star[a];
    for (size_t k = 0; k < 4; ++k) {
      const int neighbour = m_adjacency.face_neighbor[static_cast<size_t>(t)][k];
      if (neighbour < t) continue;  // none, or the pair is seen from the other side
      const auto b = static_cast<size_t>(std::find(star.begin(), star.end(), neighbour) - star.begin());
      if (b == star.size()) continue;
      const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
      std::array<Eigen::Vector3d, 3> corners;
      for (size_t c = 0; c < 3; ++c)
        corners[c] = m_mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(TET_FACES[k][c])])];
      batch.faces.push_back(
          EnrichBatch::StarFace{a, b, corners, 1e-9 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).norm()});
    }
  }
}

// Joins the nodes `members` of one key (elements 0 .. n - 1) and the star's uncut tets (elements n,
// n + 1, ...) where two of them share a face with material of both on it: batch.parent_of.
void DeformableBody::join_star_pieces(std::span<const int> star, const std::vector<size_t>& members,
                                      EnrichBatch& batch) const {
  const std::vector<EnrichBatch::Plan>& plans = batch.plans;
  const std::vector<int>& plan_of_tet = batch.plan_of_tet;
  const std::vector<EnrichBatch::Node>& nodes = batch.nodes;
  std::vector<int>& parent_of = batch.parent_of;
  std::vector<std::vector<int>>& elements = batch.elements;
  const auto find = [&](int i) { return find_root(parent_of, i); };
  const auto geometry_of = [&](int t) -> const CutTetGeometry& {
    const int p = plan_of_tet[static_cast<size_t>(t)];
    return p >= 0 ? plans[static_cast<size_t>(p)].geometry : m_cut_geometry[static_cast<size_t>(cut_tet_index(t))];
  };
  const auto is_uncut = [&](int t) { return plan_of_tet[static_cast<size_t>(t)] < 0 && cut_tet_index(t) < 0; };
  static const CutTetGeometry WHOLE{{}, {TetPiece{}}, {}};  // an uncut tet as a piece bounded by nothing
  const size_t n = members.size();
  for (auto& list : elements) list.clear();
  size_t count = n;
  for (size_t s = 0; s < star.size(); ++s) {
    if (is_uncut(star[s])) elements[s].push_back(static_cast<int>(count++));
  }
  for (size_t m = 0; m < n; ++m) {
    const auto s = static_cast<size_t>(std::find(star.begin(), star.end(), nodes[members[m]].tet) - star.begin());
    elements[s].push_back(static_cast<int>(m));
  }
  parent_of.resize(count);
  for (size_t i = 0; i < count; ++i) parent_of[i] = static_cast<int>(i);
  for (const EnrichBatch::StarFace& face : batch.faces) {
    for (const int i : elements[face.a]) {
      for (const int j : elements[face.b]) {
        if (find(i) == find(j)) continue;
        const bool i_piece = static_cast<size_t>(i) < n;
        const bool j_piece = static_cast<size_t>(j) < n;
        const double area = !i_piece && !j_piece
                                ? 1.0
                                : shared_face_area(face.corners, i_piece ? geometry_of(star[face.a]) : WHOLE,
                                                   i_piece ? nodes[members[static_cast<size_t>(i)]].piece : 0,
                                                   j_piece ? geometry_of(star[face.b]) : WHOLE,
                                                   j_piece ? nodes[members[static_cast<size_t>(j)]].piece : 0);
        if (area > face.area_threshold) parent_of[static_cast<size_t>(find(j))] = find(i);
      }
    }
  }
}

// copy_separated_by(), the batch's new held copies included.
const SeparatingCuts& DeformableBody::planned_copy_cuts(int ghost_row, const EnrichBatch& batch) const {
  if (is_held_copy(ghost_row)) {
    const auto held = static_cast<size_t>(held_copy_index(ghost_row));
    if (held >= m_held_copies.size()) return batch.new_held[held - m_held_copies.size()].separated_by;
  }
  return copy_separated_by(ghost_row);
}

// Whether the component `root` of the key's nodes around fixed vertex v touches held material: one
// of its pieces lies in a held tet, or it joins an uncut held tet of the star (join_star_pieces:
// elements n, n + 1, ... are the star's uncut tets, in star order). Its material at v is then held
// (Dirichlet on the material, not on the mesh's vertices only): the copy is held.
bool DeformableBody::touches_held_material(int v, std::span<const int> star, const std::vector<size_t>& members,
                                           int root, EnrichBatch& batch) const {
  if (vertex_block_row(v) >= 0) return false;
  const auto find = [&](int i) { return find_root(batch.parent_of, i); };
  for (size_t m = 0; m < members.size(); ++m) {
    if (find(static_cast<int>(m)) == root && held_tet(batch.nodes[members[m]].tet)) return true;
  }
  for (size_t s = 0; s < star.size(); ++s) {
    const int t = star[s];
    const bool uncut = batch.plan_of_tet[static_cast<size_t>(t)] < 0 && cut_tet_index(t) < 0;
    if (uncut && held_tet(t) && find(batch.elements[s].front()) == root) return true;
  }
  return false;
}

// Each component of the key's nodes (join_star_pieces) keeps the row (a held component: the held
// copy) most of its nodes use (one component per row), or gets a new one.
void DeformableBody::assign_ghost_rows(int v, std::span<const int> star, const std::vector<size_t>& members,
                                       EnrichBatch& batch) const {
  std::vector<EnrichBatch::Plan>& plans = batch.plans;
  std::vector<int>& plan_of_tet = batch.plan_of_tet;
  const std::vector<EnrichBatch::Node>& nodes = batch.nodes;
  std::vector<int>& parent_of = batch.parent_of;
  const auto find = [&](int i) { return find_root(parent_of, i); };
  const size_t n = members.size();
  std::vector<int> claimed;
  std::vector<int> roots;
  for (size_t m = 0; m < n; ++m) {
    const int root = find(static_cast<int>(m));
    if (std::find(roots.begin(), roots.end(), root) == roots.end()) roots.push_back(root);
  }
  for (const int root : roots) {
    const bool held = touches_held_material(v, star, members, root, batch);
    std::map<int, int> votes;
    for (size_t m = 0; m < n; ++m) {
      const int candidate = nodes[members[m]].candidate;
      if (find(static_cast<int>(m)) == root && candidate != -1 && is_held_copy(candidate) == held) ++votes[candidate];
    }
    int row = -1;
    int best = 0;
    for (const auto& [candidate, voters] : votes) {
      if (voters > best && std::find(claimed.begin(), claimed.end(), candidate) == claimed.end()) {
        row = candidate;
        best = voters;
      }
    }
    if (row == -1 && held) {
      row = HELD_COPY_FIRST + static_cast<int>(m_held_copies.size() + batch.new_held.size());
      const SeparatingCuts& key = nodes[members.front()].key;
      batch.new_held.push_back(EnrichedDof{v, key.cut_id[0], key.side[0], row, key});
    } else if (row == -1) {
      row = -2 - static_cast<int>(batch.new_rows.size());
      batch.new_rows.push_back(nodes[members.front()].key);
      batch.new_row_vertex.push_back(v);
    }
    claimed.push_back(row);
    for (size_t m = 0; m < n; ++m) {
      if (find(static_cast<int>(m)) != root) continue;
      const EnrichBatch::Node& node = nodes[members[m]];
      int p = plan_of_tet[static_cast<size_t>(node.tet)];
      if (p < 0) {
        const int k = cut_tet_index(node.tet);
        if (m_xfem.piece(k, static_cast<int>(node.piece)).ghost_row[node.local] == row) continue;
        // An existing cut tet whose piece moves to another ghost: made again with its ghosts.
        EnrichBatch::Plan plan;
        plan.tet = node.tet;
        plan.old = k;
        plan.from_cut = false;
        plan.geometry = m_cut_geometry[static_cast<size_t>(k)];
        for (int q = 0; q < static_cast<int>(m_xfem.piece_count(k)); ++q)
          plan.rows.push_back(m_xfem.piece(k, q).ghost_row);
        p = static_cast<int>(plans.size());
        plan_of_tet[static_cast<size_t>(node.tet)] = p;
        plans.push_back(std::move(plan));
      }
      plans[static_cast<size_t>(p)].rows[node.piece][node.local] = row;
    }
  }
}

}  // namespace tissue
