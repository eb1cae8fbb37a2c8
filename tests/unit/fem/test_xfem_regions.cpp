// Cuts across materials (issue 25): a cut tet's pieces keep its region's material, and the piece a
// complete cut frees carries the mass of its regions' densities exactly, and their mass damping.
#include "core/mesh/box_mesh.hpp"
#include "support/two_regions.hpp"
#include "fem/xfem_test_helpers.hpp"

#include <gtest/gtest.h>

namespace tissue {
namespace {

using xfem_test::Plane;

constexpr double SOFT_DENSITY = 1000.0, STIFF_DENSITY = 2000.0, SIDE_M = 0.02;
constexpr double BODY_ALPHA_PER_S = 3.0, STIFF_ALPHA_PER_S = 7.0;  // the soft region takes the body's

// A 0.1 x 0.02 x 0.02 m beam held at x = 0: "soft" for x < 0.05, "stiff" (E 10x, twice as dense,
// its own mass damping) beyond.
struct TwoMaterialBeam {
  TetMesh mesh = test::split_at_x(make_box_mesh(10, 2, 2, 0.01), 0.05, {"soft", Material{1.0e5, 0.3, SOFT_DENSITY}},
                                  {"stiff", Material{1.0e6, 0.3, STIFF_DENSITY, STIFF_ALPHA_PER_S}});
  DeformableBody body{mesh, settings(mesh)};

  static BodySettings settings(const TetMesh& mesh) {
    BodySettings s;
    s.damping.mass_damping_per_s = BODY_ALPHA_PER_S;
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) s.fixed_vertices.push_back(v);
    }
    return s;
  }
  // The lumped `mass` (or mass damping) of the free piece beyond a complete cut at x = cut_x (see
  // XfemBeam.CompletelyCutPieceFallsFreely): the real vertices beyond, and the ghosts of those
  // before (side -1), which the parts beyond use.
  double free_piece_sum(double cut_x, const Eigen::VectorXd& mass) const {
    double total = 0.0;
    for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
      const int vertex = body.dofs().row_vertex[static_cast<size_t>(row)];
      if (mesh.rest_positions_m[static_cast<size_t>(vertex)].x() > cut_x) total += mass(3 * row);
    }
    for (const EnrichedDof& dof : body.enriched_dofs()) {
      if (dof.side == -1) total += mass(3 * dof.row);
    }
    return total;
  }
};

TEST(XfemRegions, CutPiecesKeepTheirTetsMaterialAndThePieceTheirDensities) {
  for (const double cut_x : {0.075, 0.025}) {  // through the stiff part; through the soft part
    SCOPED_TRACE(cut_x);
    TwoMaterialBeam beam;
    const double mass_before = beam.body.total_mass_kg();
    const auto cuts = xfem_test::plane_cuts(beam.mesh, Plane{Eigen::Vector3d::UnitX(), cut_x});
    ASSERT_EQ(cuts.size(), 20u);
    beam.body.enrich(cuts);
    ASSERT_EQ(beam.body.cut_tets().size(), 20u);
    for (size_t k = 0; k < beam.body.cut_tets().size(); ++k) {
      const int tet = beam.body.cut_tets()[k].cut.tet;
      EXPECT_EQ(beam.body.xfem().rest(static_cast<int>(k)).material, beam.mesh.region_of(tet));
      EXPECT_EQ(beam.mesh.region_of(tet), cut_x > 0.05 ? 1 : 0);
    }
    EXPECT_NEAR(beam.body.total_mass_kg(), mass_before, 1e-12 * mass_before);
    const double area = SIDE_M * SIDE_M;
    const double expected = cut_x > 0.05 ? STIFF_DENSITY * (0.1 - cut_x) * area
                                         : SOFT_DENSITY * (0.05 - cut_x) * area + STIFF_DENSITY * 0.05 * area;
    EXPECT_NEAR(beam.free_piece_sum(cut_x, beam.body.mass_kg()), expected, 1e-12 * expected);
    // Its mass damping: alpha rho V of each region's part.
    const double expected_damping = cut_x > 0.05 ? STIFF_ALPHA_PER_S * STIFF_DENSITY * (0.1 - cut_x) * area
                                                 : BODY_ALPHA_PER_S * SOFT_DENSITY * (0.05 - cut_x) * area +
                                                       STIFF_ALPHA_PER_S * STIFF_DENSITY * 0.05 * area;
    EXPECT_NEAR(beam.free_piece_sum(cut_x, beam.body.mass_damping_kg_per_s()), expected_damping,
                1e-12 * expected_damping);
  }
}

}  // namespace
}  // namespace tissue
