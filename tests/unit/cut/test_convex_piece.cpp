// Convex pieces of a tet between cut planes (convex_piece.hpp, issue 21): volumes against closed forms
// and against the single-cut part volumes (cut_geometry.hpp), the arrangement's cells against the
// tet's volume and against a count of grid points, and the degenerate planes (through a vertex,
// along a face).
#include "core/fem/convex_piece.hpp"
#include "core/fem/tet_pieces.hpp"
#include "core/cut/cut_geometry.hpp"
#include "core/mesh/topology.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

namespace tissue {
namespace {

using Corners = std::array<Eigen::Vector3d, 4>;

const Corners UNIT_TET{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.0, 0.0),
                       Eigen::Vector3d(0.0, 0.0, 1.0)};
constexpr double TOLERANCE_M = 1e-12;

double tet_volume(const Corners& x) { return std::abs((x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0]))) / 6.0; }

TEST(ConvexPiece, TheWholeTetHasItsVolumeAndCentroidInEitherOrientation) {
  Corners flipped = UNIT_TET;
  std::swap(flipped[1], flipped[2]);
  for (const Corners& x : {UNIT_TET, flipped}) {
    const ConvexPiece piece = ConvexPiece::tet(x);
    EXPECT_NEAR(piece.volume_m3(), 1.0 / 6.0, 1e-15);
    EXPECT_LT((piece.centroid_m() - Eigen::Vector3d::Constant(0.25)).norm(), 1e-15);
  }
}

// The unit tet x, y, z >= 0, x + y + z <= 1 cut by x = a and y = b (a + b < 1): the corner x > a,
// y > b is the tet x' + y' + z <= 1 - a - b, volume (1 - a - b)^3 / 6, and x > a alone leaves
// (1 - a)^3 / 6. The four cells of the X add up to 1/6. Exact planes: to 1e-15.
TEST(ConvexPiece, TwoCrossingPlanesCutTheCellsTheClosedFormsGive) {
  const double a = 0.2, b = 0.3;
  const std::array<CutPlane, 2> planes{CutPlane{Eigen::Vector3d::UnitX(), a}, CutPlane{Eigen::Vector3d::UnitY(), b}};
  std::vector<PieceCell> cells, scratch;
  arrangement_cells(UNIT_TET, planes, TOLERANCE_M, cells, scratch);
  ASSERT_EQ(cells.size(), 4u);
  const auto volume_of = [&](std::uint32_t above) {
    for (const PieceCell& cell : cells) {
      if (cell.above == above) return cell.piece.volume_m3();
    }
    return -1.0;
  };
  const double both = std::pow(1.0 - a - b, 3) / 6.0;
  const double x_only = std::pow(1.0 - a, 3) / 6.0 - both;
  const double y_only = std::pow(1.0 - b, 3) / 6.0 - both;
  EXPECT_NEAR(volume_of(0b11u), both, 1e-15);
  EXPECT_NEAR(volume_of(0b01u), x_only, 1e-15);
  EXPECT_NEAR(volume_of(0b10u), y_only, 1e-15);
  EXPECT_NEAR(volume_of(0b00u), 1.0 / 6.0 - both - x_only - y_only, 1e-15);
  // A plane that misses the corner cell x > a, y > b (x + y = 0.4 < a + b) splits only the others.
  const std::array<CutPlane, 3> three{planes[0], planes[1], CutPlane{Eigen::Vector3d(1.0, 1.0, 0.0), 0.4}};
  arrangement_cells(UNIT_TET, three, TOLERANCE_M, cells, scratch);
  double sum = 0.0;
  for (const PieceCell& cell : cells) sum += cell.piece.volume_m3();
  EXPECT_NEAR(sum, 1.0 / 6.0, 1e-15);
  EXPECT_EQ(cells.size(), 7u);  // the 0b11 cell whole (x + y > 0.5 there), the three others split in two
}

// One plane: the two pieces are the single-cut parts of cut_geometry (part_volume through the
// plane's edge crossings), for 1-3 and 2-2 splits of a skewed tet.
TEST(ConvexPiece, OnePlaneGivesTheSingleCutsPartVolumes) {
  const Corners x{Eigen::Vector3d(0.01, -0.02, 0.0), Eigen::Vector3d(1.1, 0.05, 0.1), Eigen::Vector3d(0.2, 0.9, -0.1),
                  Eigen::Vector3d(0.3, 0.25, 1.2)};
  const std::array<CutPlane, 3> planes{CutPlane{Eigen::Vector3d(0.3, 0.2, 1.0), 0.8},     // 1-3: vertex 3 above
                                       CutPlane{Eigen::Vector3d(1.0, 0.1, -0.2), 0.45},   // 2-2
                                       CutPlane{Eigen::Vector3d(-0.4, 1.0, 0.3), 0.3}};  // 2-2
  for (const CutPlane& plane : planes) {
    unsigned group = 0;
    std::array<Eigen::Vector3d, 6> cut_points{};
    for (int i = 0; i < 4; ++i) {
      if (plane.signed_distance(x[static_cast<std::size_t>(i)]) > 0.0) group |= 1u << static_cast<unsigned>(i);
    }
    ASSERT_NE(group, 0u);
    ASSERT_NE(group, 15u);
    for (std::size_t k = 0; k < 6; ++k) {
      const Eigen::Vector3d& p = x[static_cast<std::size_t>(TET_EDGES[k][0])];
      const Eigen::Vector3d& q = x[static_cast<std::size_t>(TET_EDGES[k][1])];
      const double dp = plane.signed_distance(p), dq = plane.signed_distance(q);
      if (dp * dq < 0.0) cut_points[k] = p + (q - p) * (dp / (dp - dq));
    }
    const double expected = std::abs(part_volume(x, group, cut_points));
    const ConvexPiece above = ConvexPiece::tet(x).clipped(plane, true, TOLERANCE_M);
    const ConvexPiece below = ConvexPiece::tet(x).clipped(plane, false, TOLERANCE_M);
    EXPECT_NEAR(above.volume_m3(), expected, 1e-14) << "group " << group;
    EXPECT_NEAR(above.volume_m3() + below.volume_m3(), tet_volume(x), 1e-14);
    EXPECT_GT(plane.signed_distance(above.centroid_m()), 0.0);
    EXPECT_LT(plane.signed_distance(below.centroid_m()), 0.0);
  }
}

// Random planes through a random tet: the cells add up to the tet, and each holds the share of a
// fine grid of the tet's barycentric points that lies on its sides of the planes (a count: 1/n^3
// of the volume per point, so to a few 1e-3 relative).
TEST(ConvexPiece, RandomArrangementsAddUpAndHoldTheirPoints) {
  std::mt19937 rng(20261126);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<PieceCell> cells, scratch;
  for (int trial = 0; trial < 20; ++trial) {
    Corners x{};
    for (Eigen::Vector3d& corner : x) corner = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    if (tet_volume(x) < 0.05) continue;
    std::vector<CutPlane> planes;
    const Eigen::Vector3d centre = 0.25 * (x[0] + x[1] + x[2] + x[3]);
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d n = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      planes.push_back(CutPlane{n, n.dot(centre) + 0.2 * unit(rng)});
    }
    arrangement_cells(x, planes, TOLERANCE_M, cells, scratch);
    double sum = 0.0;
    for (const PieceCell& cell : cells) sum += cell.piece.volume_m3();
    EXPECT_NEAR(sum, tet_volume(x), 1e-13 * tet_volume(x)) << "trial " << trial;
    constexpr int N = 60;
    std::vector<int> counts(cells.size(), 0);
    int total = 0;
    for (int i = 0; i < N; ++i) {
      for (int j = 0; i + j < N; ++j) {
        for (int k = 0; i + j + k < N; ++k) {
          const double l1 = (i + 0.25) / N, l2 = (j + 0.25) / N, l3 = (k + 0.25) / N;
          const Eigen::Vector3d p = x[0] + l1 * (x[1] - x[0]) + l2 * (x[2] - x[0]) + l3 * (x[3] - x[0]);
          std::uint32_t above = 0;
          for (std::size_t c = 0; c < planes.size(); ++c) {
            if (planes[c].signed_distance(p) > 0.0) above |= 1u << static_cast<unsigned>(c);
          }
          ++total;
          for (std::size_t c = 0; c < cells.size(); ++c) {
            if (cells[c].above == above) ++counts[c];
          }
        }
      }
    }
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const double share = cells[c].piece.volume_m3() / tet_volume(x);
      EXPECT_NEAR(static_cast<double>(counts[c]) / total, share, 0.01 + 0.05 * share) << "trial " << trial << " cell " << c;
    }
  }
}

// A plane through a vertex, one along a face, one that misses: no empty or sliver cells, the
// volume kept whole on the right side.
TEST(ConvexPiece, DegeneratePlanesLeaveNoSlivers) {
  std::vector<PieceCell> cells, scratch;
  // Through vertex 0 and the midpoint of the opposite edge: two halves.
  const std::array<CutPlane, 1> through_vertex{CutPlane{Eigen::Vector3d(1.0, -1.0, 0.0), 0.0}};
  arrangement_cells(UNIT_TET, through_vertex, TOLERANCE_M, cells, scratch);
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_NEAR(cells[0].piece.volume_m3(), 1.0 / 12.0, 1e-15);
  EXPECT_NEAR(cells[1].piece.volume_m3(), 1.0 / 12.0, 1e-15);
  // The plane z = 0 of the tet's own face: one cell, above it.
  const std::array<CutPlane, 1> along_face{CutPlane{Eigen::Vector3d::UnitZ(), 0.0}};
  arrangement_cells(UNIT_TET, along_face, TOLERANCE_M, cells, scratch);
  ASSERT_EQ(cells.size(), 1u);
  EXPECT_EQ(cells[0].above, 1u);
  EXPECT_NEAR(cells[0].piece.volume_m3(), 1.0 / 6.0, 1e-15);
  // A plane beyond the tet.
  const std::array<CutPlane, 1> beyond{CutPlane{Eigen::Vector3d::UnitZ(), 2.0}};
  arrangement_cells(UNIT_TET, beyond, TOLERANCE_M, cells, scratch);
  ASSERT_EQ(cells.size(), 1u);
  EXPECT_EQ(cells[0].above, 0u);
}

TEST(ConvexPiece, MoreThanTheCapacityOfPlanesIsRefused) {
  std::vector<CutPlane> planes(MAX_PIECE_CUTS + 1, CutPlane{Eigen::Vector3d::UnitX(), 0.1});
  std::vector<PieceCell> cells, scratch;
  EXPECT_THROW(arrangement_cells(UNIT_TET, planes, TOLERANCE_M, cells, scratch), std::length_error);
}

// --- pieces of a tet cut several times (tet_pieces.hpp) --------------------------------------------

// The TetCut a plane makes in the tet x: sides by the plane's sign, crossings on the edges it crosses,
// the fraction above from the clipped piece.
TetCut cut_by(const std::array<Eigen::Vector3d, 4>& x, const CutPlane& plane, int cut_id) {
  TetCut cut;
  cut.cut_id = cut_id;
  cut.min_volume_fraction = 1e-3;
  std::array<double, 4> f{};
  for (size_t i = 0; i < 4; ++i) {
    f[i] = plane.signed_distance(x[i]);
    cut.side[i] = f[i] > 0.0 ? 1 : -1;
  }
  for (size_t e = 0; e < 6; ++e) {
    const double a = f[static_cast<size_t>(TET_EDGES[e][0])], b = f[static_cast<size_t>(TET_EDGES[e][1])];
    if ((a > 0.0) != (b > 0.0)) cut.edge_ratio[e] = a / (a - b);
  }
  cut.volume_fraction_above = ConvexPiece::tet(x).clipped(plane, true, 0.0).volume_m3() / ConvexPiece::tet(x).volume_m3();
  return cut;
}

TEST(TetPieces, ACrossingCutSplitsBothPiecesAndAFarCutOnlyTheOneItReaches) {
  const double s = 0.01;
  const std::array<Eigen::Vector3d, 4> x{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(s, 0, 0), Eigen::Vector3d(0, s, 0),
                                         Eigen::Vector3d(0, 0, s)};
  const double volume = ConvexPiece::tet(x).volume_m3();
  const std::vector<CutPlane> planes{CutPlane{Eigen::Vector3d::UnitX(), 0.3 * s}, CutPlane{Eigen::Vector3d::UnitY(), 0.2 * s},
                                     CutPlane{Eigen::Vector3d::UnitZ(), 0.8 * s}};
  std::vector<TetCut> cuts;
  for (int c = 0; c < 3; ++c) cuts.push_back(cut_by(x, planes[static_cast<size_t>(c)], c));

  // Each cut's plane through its crossings is the plane that made it.
  for (int c = 0; c < 3; ++c) {
    const CutPlane plane = cut_plane(x, cuts[static_cast<size_t>(c)]);
    EXPECT_NEAR(plane.normal.dot(planes[static_cast<size_t>(c)].normal), 1.0, 1e-12);
    EXPECT_NEAR(plane.offset, planes[static_cast<size_t>(c)].offset, 1e-15);
  }
  const std::vector<TetPiece> one = split_pieces(x, std::span(cuts).first(1), {});
  ASSERT_EQ(one.size(), 2u);
  EXPECT_DOUBLE_EQ(one[0].volume_fraction, cuts[0].volume_fraction_above);

  // The X: four cells, each the arrangement's, two from each parent.
  const std::vector<TetPiece> two = split_pieces(x, std::span(cuts).first(2), one);
  ASSERT_EQ(two.size(), 4u);
  std::vector<PieceCell> cells, scratch;
  arrangement_cells(x, std::span(planes).first(2), 0.0, cells, scratch);
  ASSERT_EQ(cells.size(), 4u);
  double total = 0.0;
  for (const TetPiece& piece : two) {
    EXPECT_EQ(piece.sides.bounded, 3u);
    EXPECT_EQ(piece.parent, (piece.sides.above & 1u) != 0 ? 0 : 1);
    total += piece.volume_fraction;
    bool matched = false;
    for (const PieceCell& cell : cells) {
      if (cell.above != piece.sides.above) continue;
      matched = true;
      EXPECT_NEAR(piece.volume_fraction, cell.piece.volume_m3() / volume, 1e-13);
      EXPECT_NEAR(piece_geometry(x, std::span(cuts).first(2), piece.sides).volume_m3(), cell.piece.volume_m3(), 1e-20);
    }
    EXPECT_TRUE(matched);
  }
  EXPECT_NEAR(total, 1.0, 1e-15);

  // z = 0.8 s reaches only the corner cell holding vertex 3 (x < 0.3 s, y < 0.2 s): the others stay
  // whole, below it.
  const std::vector<TetPiece> three = split_pieces(x, cuts, two);
  ASSERT_EQ(three.size(), 5u);
  total = 0.0;
  for (const TetPiece& piece : three) {
    total += piece.volume_fraction;
    const bool split = (piece.sides.bounded & 4u) != 0;
    const PieceSides& parent = two[static_cast<size_t>(piece.parent)].sides;
    EXPECT_EQ(split, parent.above == 0u) << "only the cell below both earlier cuts";
    if (!split) {
      EXPECT_EQ(piece.sides.above & 4u, 0u) << "a piece the cut does not reach takes the side holding it";
    }
  }
  EXPECT_NEAR(total, 1.0, 1e-15);
  // Every vertex lies in exactly one piece.
  for (int j = 0; j < 4; ++j) {
    int holders = 0;
    for (const TetPiece& piece : three) holders += vertex_in_piece(cuts, piece.sides, j) ? 1 : 0;
    EXPECT_EQ(holders, 1) << "vertex " << j;
  }
}

// A later cut that takes a sliver off a piece (here 2e-5 of the tet, under the smallest fraction
// 1e-3) still splits it: the tet beside it, where the same plane cuts more, splits its piece too, and
// the two must agree on their shared face (issue 43: left whole, the drawn surfaces disagreed). The
// sliver's fraction is clamped up to the smallest, from its sibling, as a first cut's is; the fractions
// still add up to 1.
TEST(TetPieces, ALaterCutSplitsASliverWithTheSmallestFraction) {
  const double s = 0.01;
  const std::array<Eigen::Vector3d, 4> x{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(s, 0, 0), Eigen::Vector3d(0, s, 0),
                                         Eigen::Vector3d(0, 0, s)};
  // x = 0.3 s, then z = (1 - c) s: the corner above it, x < 0.3 s, holds c^3 of the tet (c = 0.027).
  const double corner = std::cbrt(2e-5);
  std::vector<TetCut> cuts{cut_by(x, CutPlane{Eigen::Vector3d::UnitX(), 0.3 * s}, 0),
                           cut_by(x, CutPlane{Eigen::Vector3d::UnitZ(), (1.0 - corner) * s}, 1)};
  const std::vector<TetPiece> one = split_pieces(x, std::span(cuts).first(1), {});
  const std::vector<TetPiece> two = split_pieces(x, cuts, one);
  ASSERT_EQ(two.size(), 3u) << "the piece x < 0.3 s split; x > 0.3 s lies below z = 0.7 s";
  double total = 0.0, sliver = 0.0;
  for (const TetPiece& piece : two) {
    total += piece.volume_fraction;
    if ((piece.sides.bounded & 2u) != 0 && (piece.sides.above & 2u) != 0) sliver = piece.volume_fraction;
  }
  EXPECT_DOUBLE_EQ(sliver, 1e-3);
  EXPECT_NEAR(total, 1.0, 1e-15);
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// A blade through a vertex (or an edge) of a tet: the cutter puts that vertex above and holds the
// crossing points 1e-6 of an edge off it (cut_from_sides), so they bunch at the vertex and their own
// plane is parallel to the far face, any lean at all. The cut's plane is the blade's: its normal, and
// the vertex on it (the render surface sorts its points by this plane; before, a tet cut at a vertex by
// the plane y = 0 had its plane's normal along (1, 1, 1)).
TEST(TetPieces, ABladeThroughAVertexOrAnEdgeGivesTheCutTheBladesPlane) {
  const double s = 0.01;
  const std::array<Eigen::Vector3d, 4> x{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(s, -s, 0.2 * s),
                                         Eigen::Vector3d(0.3 * s, -s, s), Eigen::Vector3d(-0.5 * s, -0.2 * s, -0.4 * s)};
  const CutPlane blade{Eigen::Vector3d::UnitY(), 0.0};  // through vertex 0
  const auto cut_with = [&](const std::array<std::int8_t, 4>& side, const Eigen::Vector3d& normal) {
    std::array<double, 6> ratio{};
    for (size_t k = 0; k < 6; ++k) {
      const double d0 = blade.signed_distance(x[static_cast<size_t>(TET_EDGES[k][0])]);
      const double d1 = blade.signed_distance(x[static_cast<size_t>(TET_EDGES[k][1])]);
      ratio[k] = d0 == d1 ? 0.5 : d0 / (d0 - d1);
    }
    TetCut cut = cut_from_sides(x, side, ratio, 1e-6, 1e-3);
    cut.blade_normal = normal;
    return cut;
  };
  const TetCut vertex_on_blade = cut_with({1, -1, -1, -1}, Eigen::Vector3d::UnitY());
  const CutPlane plane = cut_plane(x, vertex_on_blade);
  EXPECT_NEAR(plane.normal.dot(Eigen::Vector3d::UnitY()), 1.0, 1e-12);
  EXPECT_NEAR(plane.signed_distance(x[0]), 0.0, 1e-6 * s);
  // Without the blade's normal (a cut given by hand), the crossing points' own plane.
  const CutPlane own = cut_plane(x, cut_with({1, -1, -1, -1}, Eigen::Vector3d::Zero()));
  EXPECT_LT(own.normal.dot(Eigen::Vector3d::UnitY()), 0.9);
  // An edge on the blade (vertices 0 and 3 moved onto it): the same.
  std::array<Eigen::Vector3d, 4> edge_on = x;
  edge_on[3].y() = 0.0;
  const auto edge_cut = [&] {
    std::array<double, 6> ratio{};
    for (size_t k = 0; k < 6; ++k) {
      const double d0 = blade.signed_distance(edge_on[static_cast<size_t>(TET_EDGES[k][0])]);
      const double d1 = blade.signed_distance(edge_on[static_cast<size_t>(TET_EDGES[k][1])]);
      ratio[k] = d0 == d1 ? 0.5 : d0 / (d0 - d1);
    }
    TetCut cut = cut_from_sides(edge_on, {1, -1, -1, 1}, ratio, 1e-6, 1e-3);
    cut.blade_normal = Eigen::Vector3d::UnitY();
    return cut;
  }();
  EXPECT_NEAR(cut_plane(edge_on, edge_cut).normal.dot(Eigen::Vector3d::UnitY()), 1.0, 1e-12);
  // A blade through the middle of the tet keeps the crossing points' plane (three places or more).
  const CutPlane middle{Eigen::Vector3d(0.1, 1.0, 0.05).normalized(), -0.5 * s};
  std::array<double, 6> ratio{};
  std::array<std::int8_t, 4> side{};
  for (size_t j = 0; j < 4; ++j) side[j] = middle.signed_distance(x[j]) >= 0.0 ? 1 : -1;
  for (size_t k = 0; k < 6; ++k) {
    const double d0 = middle.signed_distance(x[static_cast<size_t>(TET_EDGES[k][0])]);
    const double d1 = middle.signed_distance(x[static_cast<size_t>(TET_EDGES[k][1])]);
    ratio[k] = d0 == d1 ? 0.5 : d0 / (d0 - d1);
  }
  TetCut through = cut_from_sides(x, side, ratio, 1e-6, 1e-3);
  through.blade_normal = Eigen::Vector3d::UnitZ();  // not used: the crossings tell
  EXPECT_NEAR(cut_plane(x, through).normal.dot(middle.normal), 1.0, 1e-12);
}

}  // namespace
}  // namespace tissue
