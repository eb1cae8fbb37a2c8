// CutRenderSurface: the caps that close the openings of the split surface (the border loops): a
// single cut's opening ear-clipped, otherwise faces walked along the chains of each cut and closed
// across junction lines and crack fronts (cut_render_surface.hpp).
#include "core/render/cut_render_surface.hpp"

#include "core/render/cut_render_detail.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace tissue {

using cut_render_detail::border_loops;
using cut_render_detail::cap_polygon;
using cut_render_detail::CapEdges;
using cut_render_detail::directed_key;
using cut_render_detail::ear_clip;
using cut_render_detail::edge_key;
using cut_render_detail::flat_holes;
using cut_render_detail::FlatHoles;
using cut_render_detail::junction_smoothed;
using cut_render_detail::merge_unfacing_switches;

namespace {

// A maximal run of a loop's points split by one cut.
struct Chain {
  int loop, first, last;  // positions in the loop
  int cut;
  int facing;  // the side of the cut the chain's material lies on (majority of its points)
};

// How a chain's end continues to the next chain of its face: the points in between.
struct Link {
  std::vector<int> bridge;
  int next_first = -1;  // first point of the next chain; -1: the face cannot be closed
};

// A crack tip (surface points between two chains of one cut, where a partial cut ends): usually one
// unsplit surface vertex; with a run of split points no piece sides (the front meeting the surface
// obliquely) more.
struct Tip {
  size_t chain;                  // the chain ending at the tip
  std::vector<int> run;          // the points up to the next chain; the front starts at the last
  int first_after;               // the next chain's first point
  int part, cut, before, after;  // before, after: the facings of the chains either side
  [[nodiscard]] int point() const { return run.back(); }
};

// The junctions' switch pairs (forward, backward): of the chains ending at a switch between two
// cuts, keyed by (material part, cut lo, cut hi, facing on lo, facing on hi), the two whose switches
// run opposite ways, forward leaving the lower cut. A key without exactly such a pair gets none.
template <typename Stray>
std::vector<std::pair<size_t, size_t>> paired_switches(
    const std::map<std::array<int, 5>, std::vector<size_t>>& switches, const std::vector<Chain>& chains,
    const Stray& stray) {
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const auto& [junction, ends] : switches) {
    std::vector<size_t> forward, backward;
    for (const size_t c : ends) {
      if (chains[c].cut == junction[1]) forward.push_back(c);
      if (chains[c].cut == junction[2]) backward.push_back(c);
    }
    if (forward.empty() || forward.size() != backward.size() || forward.size() + backward.size() != ends.size()) continue;
    if (forward.size() == 1) {
      pairs.emplace_back(forward[0], backward[0]);
      continue;
    }
    // Several junction lines in one quadrant of one part (strokes closer than a tet): each forward
    // switch with the backward one whose line strays least from the cuts' junction direction.
    std::vector<std::tuple<double, size_t, size_t>> candidates;
    for (const size_t f : forward) {
      for (const size_t b : backward) candidates.emplace_back(stray(f, b), f, b);
    }
    std::sort(candidates.begin(), candidates.end());
    std::vector<size_t> taken;
    for (const auto& [unused, f, b] : candidates) {
      if (std::find(taken.begin(), taken.end(), f) != taken.end() ||
          std::find(taken.begin(), taken.end(), b) != taken.end())
        continue;
      taken.push_back(f);
      taken.push_back(b);
      pairs.emplace_back(f, b);
    }
  }
  return pairs;
}

// The crack fronts' tip pairs: each tip with the nearest unpaired tip of the same material part and
// cut whose loop turns the other way (its facings swapped). `paired`: the tips taken (in and out).
std::vector<std::pair<size_t, size_t>> paired_tips(const std::vector<Tip>& tips,
                                                   const std::vector<Eigen::Vector3d>& rest_m,
                                                   std::vector<bool>& paired) {
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t a = 0; a < tips.size(); ++a) {
    if (paired[a]) continue;
    size_t best = tips.size();
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t b = 0; b < tips.size(); ++b) {
      if (b == a || paired[b] || tips[b].part != tips[a].part || tips[b].cut != tips[a].cut ||
          tips[b].before != tips[a].after || tips[b].after != tips[a].before)
        continue;
      const double distance =
          (rest_m[static_cast<size_t>(tips[a].point())] - rest_m[static_cast<size_t>(tips[b].point())]).norm();
      if (distance < nearest) {
        nearest = distance;
        best = b;
      }
    }
    if (best == tips.size()) continue;
    paired[a] = paired[best] = true;
    pairs.emplace_back(a, best);
  }
  return pairs;
}

// The faces: chain, link, chain, ... back to the first. Returns how many walks did not close.
int walk_faces(const std::vector<std::vector<int>>& loops, const std::vector<Chain>& chains,
               const std::map<size_t, Link>& link, const std::map<int, size_t>& chain_starting_at,
               std::vector<std::vector<int>>& faces) {
  int open = 0;
  std::vector<bool> used(chains.size(), false);
  for (size_t first = 0; first < chains.size(); ++first) {
    if (used[first]) continue;
    std::vector<int> face;
    size_t at = first;
    bool closed = false;
    for (size_t guard = 0; guard <= chains.size(); ++guard) {
      used[at] = true;
      const Chain& chain = chains[at];
      const std::vector<int>& loop = loops[static_cast<size_t>(chain.loop)];
      for (size_t i = static_cast<size_t>(chain.first);; i = (i + 1) % loop.size()) {
        face.push_back(loop[i]);
        if (i == static_cast<size_t>(chain.last)) break;
      }
      const auto out = link.find(at);
      if (out == link.end() || out->second.next_first < 0) break;
      face.insert(face.end(), out->second.bridge.begin(), out->second.bridge.end());
      const auto following = chain_starting_at.find(out->second.next_first);
      if (following == chain_starting_at.end()) break;
      if (following->second == first) {
        closed = true;
        break;
      }
      at = following->second;
      if (used[at]) break;
    }
    if (closed) {
      faces.push_back(std::move(face));
    } else {
      ++open;
    }
  }
  return open;
}

using SimpleCaps =
    std::map<std::vector<int>, std::vector<std::array<int, 3>>>;  // loop (from its smallest point) -> cap

// Adds the directed edges at split points of triangles[first, end) (the split surface's, later the
// caps'). (An edge between two of the surface's own vertices keeps both its triangles: never a border.)
void find_split_edges(const std::vector<std::array<int, 3>>& triangles, size_t first, size_t points, CapEdges& edges) {
  const int vertices = edges.vertices;
  edges.directed.reserve(8 * (points - static_cast<size_t>(vertices)) + 64);
  for (size_t t = first; t < triangles.size(); ++t) {
    const auto& [a, b, c] = triangles[t];
    if (a < vertices && b < vertices && c < vertices) continue;
    for (const auto& [u, v] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      if (u >= vertices || v >= vertices) ++edges.directed[directed_key(u, v)];
    }
  }
  edges.caps.reserve(edges.directed.size() + 64);
}

// The cap of a loop on one cut, the opening of a piece cut free by one plane. The same loop as at the
// last re-mesh (same points, which an incremental re-mesh keeps) gets its cap as it was (`last`,
// unless from scratch); `caps` keeps it for the next.
void cap_single_cut_loop(const std::vector<int>& loop, const SimpleCaps& last, bool from_scratch,
                         const std::vector<Eigen::Vector3d>& rest_m, std::vector<std::array<int, 3>>& triangles,
                         CapEdges& edges, SimpleCaps& caps) {
  std::vector<int> key_points(loop);
  std::rotate(key_points.begin(), std::min_element(key_points.begin(), key_points.end()), key_points.end());
  const auto kept = from_scratch ? last.end() : last.find(key_points);
  const size_t before = triangles.size();
  if (kept != last.end()) {
    for (const auto& triangle : kept->second) {
      triangles.push_back(triangle);
      edges.add(triangle);
    }
  } else {
    cap_polygon(loop, rest_m, triangles, edges);
  }
  caps.emplace(std::move(key_points), std::vector<std::array<int, 3>>(
                                          triangles.begin() + static_cast<std::ptrdiff_t>(before), triangles.end()));
}

// The loops' points' cuts (junction_smoothed). A run of one cut whose points lie on no side of it
// (they ride on uncut tets: split only because their ends lie in two material parts) between two
// unsplit points is where the crack front meets the surface obliquely: unlabelled, it becomes part of
// the tip around it. facing(point, cut): as in cap_loops.
template <typename Facing>
std::vector<std::vector<int>> loop_labels(const std::vector<std::vector<int>>& loops, const std::vector<int>& point_cut,
                                          const Facing& facing) {
  std::vector<std::vector<int>> labels;
  for (const std::vector<int>& loop : loops) {
    std::vector<int> cuts;
    for (const int point : loop) cuts.push_back(point_cut[static_cast<size_t>(point)]);
    labels.push_back(junction_smoothed(std::move(cuts)));
  }
  for (size_t l = 0; l < loops.size(); ++l) {
    std::vector<int>& label = labels[l];
    const size_t n = label.size();
    for (size_t i = 0; i < n; ++i) {
      if (label[i] < 0 || label[(i + n - 1) % n] >= 0) continue;
      size_t j = i;
      int votes = 0;
      while (label[(j + 1) % n] == label[i] && j + 1 < i + n) {
        votes += std::abs(facing(loops[l][j % n], label[i]));
        ++j;
      }
      votes += std::abs(facing(loops[l][j % n], label[i]));
      if (votes == 0 && label[(j + 1) % n] < 0 && j + 1 < i + n) {
        for (size_t k = i; k <= j; ++k) label[k % n] = -1;
      }
    }
  }
  return labels;
}

// Loop l's chains: maximal runs of points split by one cut, each facing the side of its cut where
// the material of most of its points lies.
template <typename Facing>
void add_chains(size_t l, const std::vector<int>& loop, const std::vector<int>& label, const Facing& facing,
                std::vector<Chain>& chains, std::map<int, size_t>& chain_starting_at) {
  const size_t n = loop.size();
  const auto cut_at = [&](size_t i) { return label[i % n]; };
  for (size_t i = 0; i < n; ++i) {
    if (cut_at(i) < 0 || cut_at(i + n - 1) == cut_at(i)) continue;
    size_t j = i;
    int votes = 0;
    while (cut_at(j + 1) == cut_at(i) && j + 1 < i + n) {
      votes += facing(loop[j % n], cut_at(i));
      ++j;
    }
    votes += facing(loop[j % n], cut_at(i));
    chains.push_back(Chain{static_cast<int>(l), static_cast<int>(i), static_cast<int>(j % n), cut_at(i),
                           votes > 0 ? 1 : (votes < 0 ? -1 : 0)});
    chain_starting_at[loop[i]] = chains.size() - 1;
  }
}

// The point `steps` after a chain's last in its loop, and that point's label.
int point_after(const std::vector<std::vector<int>>& loops, const Chain& chain, int steps) {
  const std::vector<int>& loop = loops[static_cast<size_t>(chain.loop)];
  return loop[(static_cast<size_t>(chain.last) + static_cast<size_t>(steps)) % loop.size()];
}
// A chain's first and last points.
int first_point(const std::vector<std::vector<int>>& loops, const Chain& chain) {
  return loops[static_cast<size_t>(chain.loop)][static_cast<size_t>(chain.first)];
}
int last_point(const std::vector<std::vector<int>>& loops, const Chain& chain) { return point_after(loops, chain, 0); }
int label_after(const std::vector<std::vector<int>>& labels, const Chain& chain, int steps) {
  const std::vector<int>& label = labels[static_cast<size_t>(chain.loop)];
  return label[(static_cast<size_t>(chain.last) + static_cast<size_t>(steps)) % label.size()];
}

// How the chains' ends continue. Switches (two cuts meet: a junction line through the body between
// the two switches of one part and cut pair that run opposite ways) and tips (a partial cut: a crack
// front between two tips of one part and cut whose loops turn opposite ways, nearest first).
struct ChainEnds {
  std::map<size_t, Link> link;  // the points to add and the chain to go on with
  // (part, cut lo, cut hi, facing on lo, facing on hi: the quadrant) -> the chains ending there
  std::map<std::array<int, 5>, std::vector<size_t>> switches;
  std::vector<Tip> tips;
  std::vector<bool> tip_taken;  // by a junction that ends inside (bridge_notches) or a crack front
};

// Each chain's end: at a switch, a tip, or (the material on one side before and after) going on
// through the surface points between it and the next chain. part_of_point(point): its material part.
template <typename PartOf>
ChainEnds find_chain_ends(const std::vector<std::vector<int>>& loops, const std::vector<std::vector<int>>& labels,
                          const std::vector<Chain>& chains, const std::map<int, size_t>& chain_starting_at,
                          const PartOf& part_of_point) {
  ChainEnds ends;
  std::map<size_t, Link>& link = ends.link;
  std::map<std::array<int, 5>, std::vector<size_t>>& switches = ends.switches;
  std::vector<Tip>& tips = ends.tips;
  for (size_t c = 0; c < chains.size(); ++c) {
    const Chain& chain = chains[c];
    const int beyond = point_after(loops, chain, 1);
    const int beyond_cut = label_after(labels, chain, 1);
    if (beyond_cut >= 0) {
      const auto after = chain_starting_at.find(beyond);
      if (after == chain_starting_at.end()) continue;
      const int after_facing = chains[after->second].facing;
      const bool up = chain.cut < beyond_cut;
      switches[{part_of_point(beyond), std::min(chain.cut, beyond_cut), std::max(chain.cut, beyond_cut),
                up ? chain.facing : after_facing, up ? after_facing : chain.facing}]
          .push_back(c);
    } else {
      std::vector<int> run{beyond};  // the unsplit points up to the next chain
      const auto length = static_cast<int>(loops[static_cast<size_t>(chain.loop)].size());
      int steps = 2;
      for (; steps <= length && label_after(labels, chain, steps) < 0; ++steps)
        run.push_back(point_after(loops, chain, steps));
      // (The next chain may be this one: a loop of one chain and its run.)
      const auto after = chain_starting_at.find(point_after(loops, chain, steps));
      if (steps > length || after == chain_starting_at.end() || chains[after->second].cut != chain.cut) continue;
      const int after_facing = chains[after->second].facing;
      if ((chain.facing != 0 && after_facing == chain.facing) || after->second == c) {
        // Not where a cut ends: the material lies on one side before and after (or the loop is this
        // chain and its run alone: a pocket), the loop only passes surface points the split left on
        // the border (their edges' tests disagreed). The face goes on through them.
        link[c] = Link{run, point_after(loops, chain, steps)};
        continue;
      }
      tips.push_back(Tip{c, run, point_after(loops, chain, steps), part_of_point(run.back()), chain.cut, chain.facing,
                         after_facing});
    }
  }
  return ends;
}

// The lines between paired switches: the lower cut's face takes both switch edges and the line; the
// higher cut's runs it back. line_points(from, to): new points between two; plane_of(point, cut): the
// plane of a cut at a point's cell (a zero normal if its cell is not cut by it).
template <typename LinePoints, typename PlaneOf>
void bridge_switches(const std::vector<std::vector<int>>& loops, const std::vector<Chain>& chains,
                     const std::vector<Eigen::Vector3d>& rest_m, const LinePoints& line_points,
                     const PlaneOf& plane_of, const std::map<std::array<int, 5>, std::vector<size_t>>& switches,
                     ChainEnds& ends) {
  std::map<size_t, Link>& link = ends.link;
  const auto line_start_of = [&](size_t forward) { return point_after(loops, chains[forward], 1); };  // on the higher cut
  const auto line_end_of = [&](size_t backward) { return last_point(loops, chains[backward]); };
  // How far a line from a forward switch to a backward one strays from the two cuts' junction.
  const auto stray = [&](size_t forward, size_t backward) {
    const int start = line_start_of(forward);
    const int before = last_point(loops, chains[forward]);
    const Eigen::Vector3d along = plane_of(before, chains[forward].cut).normal.cross(plane_of(start, chains[backward].cut).normal);
    const Eigen::Vector3d v = rest_m[static_cast<size_t>(line_end_of(backward))] - rest_m[static_cast<size_t>(start)];
    if (along.norm() < 1e-6) return v.norm();
    const Eigen::Vector3d d = along.normalized();
    return (v - v.dot(d) * d).norm();
  };
  for (const auto& [forward, backward] : paired_switches(switches, chains, stray)) {
    const int line_start = line_start_of(forward);
    const int line_end = line_end_of(backward);
    const std::vector<int> line = line_points(line_start, line_end);
    Link& out = link[forward];
    out.bridge.push_back(line_start);
    out.bridge.insert(out.bridge.end(), line.begin(), line.end());
    out.bridge.push_back(line_end);
    out.next_first = point_after(loops, chains[backward], 1);  // back on the lower cut
    Link& back = link[backward];
    back.bridge.assign(line.rbegin(), line.rend());
    back.next_first = line_start;
  }
}

// Where a partial cut meets a cut through the body only part of the way (its crack turns away from
// the junction inside the body, a notch in the through cut's face): two switches without a partner,
// x where a chain of the through cut K ends and one of the notched cut N begins, y where an N chain
// ends and a K chain begins (same part, the same side of K, opposite sides of N), and a tip of N in
// that part between the two walls. The junction runs from x into the body to a point J (the tip
// projected onto K's plane, plane_of(point, cut)), and back to y; the crack front from the tip to J.
// K's face takes the notch (x, J, y); N's walls take the junction and the front on either side.
template <typename LinePoints, typename PointAt, typename PlaneOf>
void bridge_notches(const std::vector<std::vector<int>>& loops, const std::vector<Chain>& chains,
                    const std::map<int, size_t>& chain_starting_at, const std::vector<Eigen::Vector3d>& rest_m,
                    const LinePoints& line_points, const PointAt& point_at, const PlaneOf& plane_of, ChainEnds& ends) {
  struct Lone {
    size_t ending, beginning;  // the chains either side of the switch
    int part;
  };
  std::vector<Lone> lone;
  for (const auto& [junction, list] : ends.switches) {
    if (list.size() != 1) continue;
    const auto next = chain_starting_at.find(point_after(loops, chains[list[0]], 1));
    if (next != chain_starting_at.end()) lone.push_back(Lone{list[0], next->second, junction[0]});
  }
  ends.tip_taken.assign(ends.tips.size(), false);
  std::vector<bool> used(lone.size(), false);
  for (size_t i = 0; i < lone.size(); ++i) {
    const Chain& k_end = chains[lone[i].ending];  // x: a K chain ends, an N chain begins
    const Chain& n_begin = chains[lone[i].beginning];
    for (size_t j = 0; j < lone.size() && !used[i]; ++j) {
      const Chain& n_end = chains[lone[j].ending];  // y: an N chain ends, a K chain begins
      const Chain& k_begin = chains[lone[j].beginning];
      if (used[j] || j == i || lone[j].part != lone[i].part || n_end.cut != n_begin.cut || k_begin.cut != k_end.cut ||
          k_begin.facing != k_end.facing || n_end.facing == n_begin.facing)
        continue;
      size_t best = ends.tips.size();
      double nearest = std::numeric_limits<double>::infinity();
      const int x_point = first_point(loops, n_begin);
      for (size_t t = 0; t < ends.tips.size(); ++t) {
        const Tip& tip = ends.tips[t];
        if (ends.tip_taken[t] || tip.part != lone[i].part || tip.cut != n_begin.cut || tip.before != n_begin.facing ||
            tip.after != n_end.facing)
          continue;
        const double distance = (rest_m[static_cast<size_t>(tip.point())] - rest_m[static_cast<size_t>(x_point)]).norm();
        if (distance < nearest) {
          nearest = distance;
          best = t;
        }
      }
      if (best == ends.tips.size()) continue;
      used[i] = used[j] = true;
      ends.tip_taken[best] = true;
      const Tip& tip = ends.tips[best];
      const int y_point = last_point(loops, n_end);
      const CutPlane k_plane = plane_of(x_point, k_end.cut);
      const Eigen::Vector3d& at_tip = rest_m[static_cast<size_t>(tip.point())];
      const int inner = point_at(tip.point(), at_tip - k_plane.signed_distance(at_tip) * k_plane.normal);  // J
      const std::vector<int> down = line_points(x_point, inner);  // x to J
      const std::vector<int> up = line_points(inner, y_point);    // J to y
      const std::vector<int> front = line_points(tip.point(), inner);
      Link& k_face = ends.link[lone[i].ending];
      k_face.bridge = {x_point};
      k_face.bridge.insert(k_face.bridge.end(), down.begin(), down.end());
      k_face.bridge.push_back(inner);
      k_face.bridge.insert(k_face.bridge.end(), up.begin(), up.end());
      k_face.bridge.push_back(y_point);
      k_face.next_first = first_point(loops, k_begin);
      Link& wall_before = ends.link[tip.chain];  // the tip, the front to J, the junction up to x
      wall_before.bridge = tip.run;
      wall_before.bridge.insert(wall_before.bridge.end(), front.begin(), front.end());
      wall_before.bridge.push_back(inner);
      wall_before.bridge.insert(wall_before.bridge.end(), down.rbegin(), down.rend());
      wall_before.next_first = x_point;
      Link& wall_after = ends.link[lone[j].ending];  // from y down to J, the front back to the tip
      wall_after.bridge.assign(up.rbegin(), up.rend());
      wall_after.bridge.push_back(inner);
      wall_after.bridge.insert(wall_after.bridge.end(), front.rbegin(), front.rend());
      wall_after.bridge.push_back(tip.point());
      wall_after.next_first = tip.first_after;
    }
  }
}

// The crack fronts between paired tips (those no junction took).
template <typename LinePoints>
void bridge_tips(const std::vector<Eigen::Vector3d>& rest_m, const LinePoints& line_points, ChainEnds& ends) {
  std::map<size_t, Link>& link = ends.link;
  const std::vector<Tip>& tips = ends.tips;
  for (const auto& [a, best] : paired_tips(tips, rest_m, ends.tip_taken)) {
    std::vector<int> front = line_points(tips[a].point(), tips[best].point());  // one crack front for both walls
    for (const auto& [from, to] : {std::pair{a, best}, std::pair{best, a}}) {
      // The wall's own tip run, the front, the other tip's front end; then the chain after it.
      Link& out = link[tips[from].chain];
      out.bridge = tips[from].run;
      out.bridge.insert(out.bridge.end(), front.begin(), front.end());
      out.bridge.push_back(tips[to].point());
      out.next_first = tips[to].first_after;
      std::reverse(front.begin(), front.end());
    }
  }
}

}  // namespace

void CutRenderSurface::cap_loops(const DeformableBody& body) {
  CapEdges edges{{}, {}, m_surface_edges, static_cast<int>(m_surface.vertices_m.size())};
  find_split_edges(m_triangles, 0, m_points.size(), edges);
  const std::vector<std::vector<int>> loops = border_loops(edges.directed);
  SimpleCaps simple_caps;  // this re-mesh's, for the next
  const size_t first_cap = m_triangles.size();  // the split skin's triangles come before
  m_open_loops = 0;
  const auto part_of_point = [&](int point) { return part_of(body, m_points[static_cast<size_t>(point)]); };
  // Which side of cut `cut` the material of a point's piece lies on (+1 above, -1 below, 0 unknown:
  // a point riding on an uncut tet).
  // Cut `cut`'s index among the cuts of a point's cell (its first, if the cell is cut by it twice);
  // -1 if the point rides on an uncut tet or its cell is not cut by it.
  const auto cut_index = [&](int point, int cut) {
    const Point& at = m_points[static_cast<size_t>(point)];
    if (at.cut_tet < 0) return -1;
    const std::vector<TetCut>& cuts = body.cut_geometry(at.cut_tet).cuts;
    for (size_t c = 0; c < cuts.size(); ++c) {
      if (cuts[c].cut_id == cut) return static_cast<int>(c);
    }
    return -1;
  };
  const auto facing = [&](int point, int cut) {
    const int c = cut_index(point, cut);
    if (c < 0) return 0;
    const Point& at = m_points[static_cast<size_t>(point)];
    return (body.cut_geometry(at.cut_tet).pieces[static_cast<size_t>(at.piece)].sides.above & (1u << c)) != 0 ? 1 : -1;
  };

  // Chains: maximal runs of points split by one cut, in loops that are not a single plane's opening.
  std::vector<Chain> chains;
  std::map<int, size_t> chain_starting_at;  // first point -> chain
  const std::vector<std::vector<int>> labels = loop_labels(loops, m_point_cut, facing);
  for (size_t l = 0; l < loops.size(); ++l) {
    const std::vector<int>& loop = loops[l];
    const size_t n = loop.size();
    const auto cut_at = [&](size_t i) { return labels[l][i % n]; };
    bool simple = true;
    for (size_t i = 0; i < n && simple; ++i) simple = cut_at(i) >= 0 && cut_at(i) == cut_at(0);
    if (simple) {  // the opening of a piece cut free by one plane
      cap_single_cut_loop(loop, m_simple_caps, m_from_scratch, m_rest_m, m_triangles, edges, simple_caps);
      continue;
    }
    add_chains(l, loop, labels[l], facing, chains, chain_starting_at);
  }
  ChainEnds ends = find_chain_ends(loops, labels, chains, chain_starting_at, part_of_point);
  const auto line = [&](int from, int to) { return line_points(from, to); };
  const auto point_at = [&](int model, const Eigen::Vector3d& rest_m) { return add_point_like(model, rest_m); };
  // The plane of cut `cut` at a point's cell (none, a zero normal, if its cell is not cut by it).
  const auto plane_of = [&](int point, int cut) {
    const int c = cut_index(point, cut);
    if (c < 0) return CutPlane{Eigen::Vector3d::Zero(), 0.0};
    return body.cut_geometry(m_points[static_cast<size_t>(point)].cut_tet).planes[static_cast<size_t>(c)];
  };
  bridge_switches(loops, chains, m_rest_m, line, plane_of, ends.switches, ends);
  bridge_notches(loops, chains, chain_starting_at, m_rest_m, line, point_at, plane_of, ends);
  // The switches still alone, those of chains that face neither side merged with their partners.
  std::map<std::array<int, 5>, std::vector<size_t>> alone;
  for (const auto& [key, list] : ends.switches) {
    if (list.size() == 1 && !ends.link.contains(list[0])) alone.emplace(key, list);
  }
  merge_unfacing_switches(alone);  // a key still alone pairs nothing (paired_switches)
  bridge_switches(loops, chains, m_rest_m, line, plane_of, alone, ends);
  bridge_tips(m_rest_m, line, ends);
  std::vector<std::vector<int>> faces;
  const int unclosed = walk_faces(loops, chains, ends.link, chain_starting_at, faces);
  for (const std::vector<int>& face : faces) cap_polygon(face, m_rest_m, m_triangles, edges);
  // Every walk closed: every loop is capped. Else the holes (the caps' edges added), flat ones filled.
  if (unclosed > 0) {
    find_split_edges(m_triangles, first_cap, m_points.size(), edges);
    const FlatHoles holes = flat_holes(
        edges.directed, m_rest_m, part_of_point, [&](int point) { return m_point_cut[static_cast<size_t>(point)]; },
        line);
    std::vector<size_t> face_first{m_triangles.size()};  // each face's first triangle, then the end
    for (const std::vector<int>& hole : holes.flat) {
      cap_polygon(hole, m_rest_m, m_triangles, edges);
      face_first.push_back(m_triangles.size());
    }
    std::vector<FilledHole> filled;
    for (const auto& p : holes.peeled) filled.push_back({p.part, face_first[p.first_face], face_first[p.end_face]});
    std::vector<std::vector<int>> refused;  // the holes whose peeled faces were dropped, peeled again
    for (const size_t h : drop_unsound_fills(body, filled, holes.open_parts)) refused.push_back(holes.peeled[h].loop);
    m_open_loops = holes.others + cut_render_detail::peel_again(
                                      std::move(refused), m_triangles, first_cap, m_rest_m, edges,
                                      [&](int point) { return m_point_cut[static_cast<size_t>(point)]; }, line);
  }
  m_cap_triangles = static_cast<int>(cut_render_detail::drop_bubbles(m_triangles, first_cap, m_rest_m, m_bubbles));
  m_simple_caps = std::move(simple_caps);
}

void cut_render_detail::cap_polygon(const std::vector<int>& polygon, const std::vector<Eigen::Vector3d>& rest_m,
                                    std::vector<std::array<int, 3>>& triangles, CapEdges& edges) {
  const size_t before = triangles.size();
  ear_clip(polygon, rest_m, triangles, [&edges](int u, int v) { return edges(u, v); });
  for (size_t t = before; t < triangles.size(); ++t) edges.add(triangles[t]);
}

}  // namespace tissue
