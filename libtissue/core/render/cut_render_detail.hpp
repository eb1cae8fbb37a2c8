// Private to core/render: the edge keys CutRenderSurface's files share (cut_render_surface.cpp,
// cut_render_split.cpp, cut_render_caps.cpp) and the caps' loops (cut_render_loops.cpp).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace tissue::cut_render_detail {

// An edge as one integer: (u, v) directed, and the same for either direction (lower, higher).
inline long long directed_key(int u, int v) { return (static_cast<long long>(u) << 32) | static_cast<unsigned int>(v); }
inline long long edge_key(int u, int v) { return directed_key(std::min(u, v), std::max(u, v)); }

// The border loops of a split surface from its directed edges at split points (a border edge has
// no twin), each in the order its cap runs them (against the skin).
std::vector<std::vector<int>> border_loops(const std::unordered_map<long long, int>& directed);

// The edges a cap must not run along (ear_clip's edge_exists): the split surface's directed edges at
// its split points (a border edge has no twin), the caps' edges so far and the surface's own.
struct CapEdges {
  std::unordered_map<long long, int> directed;   // (u, v) -> count
  std::unordered_set<long long> caps;            // (lower, higher) of the caps' edges so far
  const std::unordered_set<long long>& surface;  // the surface's own edges
  int vertices;                                  // the surface's vertices: the points below

  bool operator()(int u, int v) const {
    const long long undirected = edge_key(u, v);
    if (caps.contains(undirected)) return true;
    if (u < vertices && v < vertices) return surface.contains(undirected);
    return directed.contains(directed_key(u, v)) || directed.contains(directed_key(v, u));
  }
  void add(const std::array<int, 3>& triangle) {
    for (size_t k = 0; k < 3; ++k) {
      const int u = triangle[k], v = triangle[(k + 1) % 3];
      caps.insert(edge_key(u, v));
    }
  }
};

// Triangulates the closed polygon `loop` (point indices, positions `x`) by ear clipping in its
// best-fit plane, wound as the polygon, never along an edge for which edge_exists(u, v) holds.
void ear_clip(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
              std::vector<std::array<int, 3>>& triangles, const std::function<bool(int, int)>& edge_exists);

// Caps a polygon (ear_clip), its edges added to `edges`.
void cap_polygon(const std::vector<int>& polygon, const std::vector<Eigen::Vector3d>& rest_m,
                 std::vector<std::array<int, 3>>& triangles, CapEdges& edges);

// A chain whose points all ride on uncut tets faces neither side of its cut (0): a switch of it alone
// under its key (part, cut lo, cut hi, facing on lo, facing on hi) joins the one lone switch whose
// key differs only there.
void merge_unfacing_switches(std::map<std::array<int, 5>, std::vector<size_t>>& switches);

// A loop's points' cuts with the short runs next to a junction given a neighbour's cut.
std::vector<int> junction_smoothed(std::vector<int> label);

// Whether the points of `loop` lie within `tolerance_m` of their least-squares plane.
bool flat_within(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x, double tolerance_m);

// Splits `loop` by a chord between two of its points into two runs each within FLAT_HOLE_M of its
// own plane (the first such chord that is not an edge already, edge_exists(u, v); loops of at most
// MAX_SPLIT_HOLE_POINTS points), appended to `flat` in the loop's order, each closed by the chord.
// Whether found.
bool split_in_two_flat(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
                       std::vector<std::vector<int>>& flat, const std::function<bool(int, int)>& edge_exists = {});

// The holes the caps' chain walks left (a switch or a tip with no partner to close on: strokes closer
// than a tet, several in one tet) are the border loops of the surface capped so far. One closed,
// all its points in one material part (part_of), and within FLAT_HOLE_M of its plane is a cap's
// face the walk missed, to be ear-clipped in that plane; one that a chord splits into two such
// halves, two faces meeting at a junction of two cuts (split_in_two_flat); another of one part is
// peeled by its cuts (peel_by_cuts, `cut_of` and `line_points` given), which the caller keeps only
// where the part then encloses its simulated volume or the faces bound the solid they close
// (CutRenderSurface::drop_unsound_fills, fills_bounding_solids). Filled
// flat, a hole around a junction drew a sheet through the piece (30 + 30 strokes, every hole filled:
// the closed surface enclosed 0.39 of the simulated volume), and one between two parts would draw a
// sheet between pieces that fall apart: those stay open.
inline constexpr double FLAT_HOLE_M = 1e-4;
inline constexpr size_t MAX_SPLIT_HOLE_POINTS = 96;
struct FlatHoles {
  std::vector<std::vector<int>> flat;  // faces to fill, in cap order (border_loops)
  int others = 0;                      // the holes left open
  std::vector<int> open_parts;         // their material parts (-1: a hole in two)
  // The holes peel_by_cuts filled: their part and their faces flat[first_face, end_face).
  struct Peeled {
    int part;
    size_t first_face, end_face;
    std::vector<int> loop;  // the hole (peel_again's, when its faces are dropped)
  };
  std::vector<Peeled> peeled;
};
FlatHoles flat_holes(const std::unordered_map<long long, int>& directed, const std::vector<Eigen::Vector3d>& x,
                     const std::function<int(int)>& part_of, const std::function<int(int)>& cut_of = {},
                     const std::function<std::vector<int>(int, int)>& line_points = {});

// Which run peel_by_cuts takes next: the one whose ends lie nearest each other (the first try), the
// one whose ends lie farthest apart, the longest, the shortest (peel_again's tries, in this order).
enum class PeelOrder { nearest_ends, farthest_ends, longest_run, shortest_run };
inline constexpr std::array<PeelOrder, 3> PEEL_AGAIN_ORDERS{PeelOrder::farthest_ends, PeelOrder::longest_run,
                                                            PeelOrder::shortest_run};

// A hole of one material part that no chord splits into two flat faces: the faces of the cuts its
// points lie on (cut_of; -1 for none) that the walk did not close. Peeled one cut's run at a time,
// the run `order` names first (by default the one whose ends lie nearest), each closed by the straight line between its
// ends (line_points(from, to): the new points between two), which the rest of the hole then runs the other way; the
// last run is the last face. Runs on no cut, or of a point or two, between two runs of one cut belong to that cut's
// run. Appends the faces to `faces` (none unless the whole hole is peeled); false for fewer than 3 points or a run left
// of a single point.
bool peel_by_cuts(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
                  const std::function<int(int)>& cut_of, const std::function<std::vector<int>(int, int)>& line_points,
                  std::vector<std::vector<int>>& faces, PeelOrder order = PeelOrder::nearest_ends);

// Whether the faces peel_by_cuts filled into a hole bound the solid they close, as drawn: behind
// each of its FILL_PROBES largest triangles, FILL_PROBE_OFFSET_M from the centroid, the shell it
// joins (the triangles joined by shared points) winds once around the point and in front of it not
// at all (the solid's face, outward), or it winds at least once on both sides (the fill lies within
// the solid, where no one sees it). Peeled faces laid back to back in the open (a sheet across a
// 2 mm column of 30 + 30 hatched strokes: a hole that runs up one wall of a cut and down the other)
// wind 0 on both sides; a face turned into its shell -1 on one.
inline constexpr double FILL_PROBE_OFFSET_M = 5e-5;
inline constexpr size_t FILL_PROBES = 3;
// The winding number of the triangles `shell` (indices into `triangles`) around `point`: the sum of
// their solid angles (Van Oosterom and Strackee 1983) over 4 pi; 1 inside a closed outward shell.
double winding_number(const std::vector<std::array<int, 3>>& triangles, const std::vector<size_t>& shell,
                      const std::vector<Eigen::Vector3d>& x, const Eigen::Vector3d& point);
// Per fill (the triangles [first, second) of `triangles`), whether it bounds a solid as above.
std::vector<char> fills_bounding_solids(const std::vector<std::array<int, 3>>& triangles,
                                        const std::vector<Eigen::Vector3d>& x,
                                        const std::vector<std::pair<size_t, size_t>>& fills);

// Removes from `triangles` the fills (ranges [first, second)) whose `keep` is 0, the order of the
// rest kept.
void drop_fills(std::vector<std::array<int, 3>>& triangles, const std::vector<std::pair<size_t, size_t>>& fills,
                const std::vector<char>& keep);

// The holes `loops` whose peeled faces neither rule kept (CutRenderSurface::drop_unsound_fills),
// peeled again in PEEL_AGAIN_ORDERS' orders in turn: each try's faces capped at the end of
// `triangles` (`edges` made again from the caps from `first_cap` on first: the dropped faces' edges
// gone), kept where they bound the solid they close (fills_bounding_solids), else dropped for the next
// order. On the hatched frog at rest the faces a peeling leaves as a sheet across a 2 mm column
// depend on which run it takes first. Returns how many holes are left open.
int peel_again(std::vector<std::vector<int>> loops, std::vector<std::array<int, 3>>& triangles, size_t first_cap,
               const std::vector<Eigen::Vector3d>& x, CapEdges& edges, const std::function<int(int)>& cut_of,
               const std::function<std::vector<int>(int, int)>& line_points);

// A closed shell of the finished surface that encloses less than BUBBLE_M3 (a cube of FLAT_HOLE_M) is
// below what the render surface resolves: a render point on a sliver piece near where two cuts meet
// (a later cut splits every piece it passes through, issue 43), all its neighbours across the planes,
// capped on its own. Such shells are not drawn.
inline constexpr double BUBBLE_M3 = FLAT_HOLE_M * FLAT_HOLE_M * FLAT_HOLE_M;
// The shells of `triangles` (the triangles joined by shared points): for each of `point_count`
// points, in `root`, the point that names its shell (union by size over the triangles' corners,
// `size` its working array; both resized here, their room kept).
void point_shells(const std::vector<std::array<int, 3>>& triangles, size_t point_count, std::vector<int>& root,
                  std::vector<int>& size);
// drop_bubbles' working arrays, kept by its caller from re-mesh to re-mesh: grown once, they are
// not allocated (and their pages not faulted in) again inside a step's slot.
struct BubbleScratch {
  std::vector<int> parent, size;      // per point
  std::vector<signed char> state;     // per point
  std::vector<double> volume_m3;      // per point
  std::vector<std::size_t> shell_of;  // per triangle
  std::unordered_map<long long, int> directed;
};
// Removes from `triangles` the closed shells (every edge used once each way) holding a triangle from
// `first_cap` on (a cap) and enclosing less than BUBBLE_M3 at `x`, keeping the order of the rest;
// returns how many of the triangles from `first_cap` on are left.
size_t drop_bubbles(std::vector<std::array<int, 3>>& triangles, size_t first_cap, const std::vector<Eigen::Vector3d>& x,
                    BubbleScratch& scratch);

}  // namespace tissue::cut_render_detail
