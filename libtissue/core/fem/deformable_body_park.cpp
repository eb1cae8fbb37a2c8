// DeformableBody: parts that fell out of the operating field taken out of the dynamics (see
// park_parts_outside in deformable_body.hpp; docs/DESIGN.md, "Parts out of the field").
#include "core/fem/body_parts.hpp"
#include "core/fem/deformable_body.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// What park_parts_outside needs of each part.
struct PartSummary {
  Eigen::AlignedBox3d box;  // of its rows' points
  Eigen::Vector3d momentum = Eigen::Vector3d::Zero();
  double mass_kg = 0.0;
  bool all_parked = true;
};

}  // namespace

const BodyParts& DeformableBody::body_parts() const {
  if (m_parts_revision != m_element_revision) {
    m_parts = find_body_parts(*this);
    m_parts_revision = m_element_revision;
  }
  return m_parts;
}

std::vector<int> DeformableBody::park_parts_outside(const Eigen::AlignedBox3d& field, DynamicState& state) {
  check_unknowns(state.displacement_m);
  if (state.velocity_m_per_s.size() != dof_count()) {
    throw std::invalid_argument("park_parts_outside: the state has " + std::to_string(state.velocity_m_per_s.size()) +
                                " velocities, the body " + std::to_string(dof_count()) + " unknowns");
  }
  const BodyParts& parts = body_parts();
  const std::vector<Eigen::Vector3d>& points = *block_positions(state.displacement_m);
  std::vector<PartSummary> summary(static_cast<size_t>(parts.count()));
  const int rows = dof_count() / 3;
  for (int row = 0; row < rows; ++row) {
    const int part = parts.part_of_row[static_cast<size_t>(row)];
    if (part < 0) continue;
    PartSummary& of = summary[static_cast<size_t>(part)];
    of.box.extend(points[static_cast<size_t>(row)]);
    const double mass_kg = m_mass_kg(3 * row);
    of.momentum += mass_kg * state.velocity_m_per_s.segment<3>(3 * row);
    of.mass_kg += mass_kg;
    of.all_parked = of.all_parked && parked(row);
  }
  const auto goes = [&](int part) {
    const PartSummary& of = summary[static_cast<size_t>(part)];
    return parts.held[static_cast<size_t>(part)] == 0 && !of.all_parked && !of.box.intersects(field);
  };
  std::vector<int> chosen;
  for (int row = 0; row < rows; ++row) {
    const int part = parts.part_of_row[static_cast<size_t>(row)];
    if (part < 0 || !goes(part)) continue;
    const PartSummary& of = summary[static_cast<size_t>(part)];
    state.velocity_m_per_s.segment<3>(3 * row) = of.momentum / of.mass_kg;
    if (!parked(row)) chosen.push_back(row);
  }
  if (!chosen.empty()) park_rows(chosen);  // (a change of the model only then: park_rows)
  return chosen;
}

void DeformableBody::park_rows(std::span<const int> rows) {
  const int row_count = dof_count() / 3;
  for (const int row : rows) {
    if (row < 0 || row >= row_count) {
      throw std::invalid_argument("park_rows: row " + std::to_string(row) + " is outside [0, " +
                                  std::to_string(row_count) + ")");
    }
  }
  changed();
  m_row_parked.resize(static_cast<size_t>(row_count), 0);
  for (const int row : rows) {
    if (m_row_parked[static_cast<size_t>(row)] == 0) ++m_parked_rows;
    m_row_parked[static_cast<size_t>(row)] = 1;
  }
  // The elements whose rows are all parked: uncut tets leave the co-rotational pass, pieces the XFEM's.
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    if (cut_tet_index(t) >= 0 || m_elasticity.is_excluded(t)) continue;
    const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
    if (std::all_of(tet.begin(), tet.end(), [&](int v) { return parked(vertex_block_row(v)); })) m_elasticity.exclude(t);
  }
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) {
    if (m_xfem.retired(k)) continue;
    for (int p = 0; p < static_cast<int>(m_xfem.piece_count(k)); ++p) {
      const std::array<int, 4> rows_of_piece = piece_rows(k, p);
      if (std::all_of(rows_of_piece.begin(), rows_of_piece.end(), [&](int row) { return parked(row); })) m_xfem.park(k, p);
    }
  }
  drop_retired_blocks();
}

}  // namespace tissue
