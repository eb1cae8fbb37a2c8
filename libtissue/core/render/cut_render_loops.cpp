// CutRenderSurface's caps: the split surface's border loops and their points' cuts, the switches of
// chains that face neither side, and the ear clipping that triangulates the faces (cut_render_caps.cpp).
#include "core/render/cut_render_detail.hpp"

#include "core/fem/union_find.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace tissue::cut_render_detail {

// Triangulates the closed polygon `loop` (point indices, positions `x`) by ear clipping in its
// best-fit plane, each triangle wound as the polygon (counter-clockwise about its Newell normal),
// never cutting along an edge the mesh has already (edge_exists(u, v), either way: it would then
// have four triangles).
void ear_clip(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
              std::vector<std::array<int, 3>>& triangles, const std::function<bool(int, int)>& edge_exists) {
  const size_t n = loop.size();
  if (n < 3) return;
  // A loop that passes a point twice (two openings of one cut touching at a surface vertex) is two
  // loops, each clipped on its own: clipped whole, a diagonal from a third point to both passes
  // gave one edge four triangles (the hatched frog through tissue-host, in most frames of 13 of 21
  // neighbouring trajectories).
  std::unordered_map<int, size_t> first_pass;
  first_pass.reserve(n);
  for (size_t j = 0; j < n; ++j) {
    const auto [at, fresh] = first_pass.try_emplace(loop[j], j);
    if (fresh) continue;
    const size_t i = at->second;
    const std::vector<int> between(loop.begin() + static_cast<std::ptrdiff_t>(i),
                                   loop.begin() + static_cast<std::ptrdiff_t>(j));
    std::vector<int> rest(loop.begin() + static_cast<std::ptrdiff_t>(j), loop.end());
    rest.insert(rest.end(), loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(i));
    ear_clip(between, x, triangles, edge_exists);
    ear_clip(rest, x, triangles, edge_exists);
    return;
  }
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    normal += x[static_cast<size_t>(loop[i])].cross(x[static_cast<size_t>(loop[(i + 1) % n])]);
  }
  std::vector<int> left = loop;
  if (normal.norm() <= 0.0) {  // no area: a fan closes it
    for (size_t i = 1; i + 1 < n; ++i) triangles.push_back({loop[0], loop[i], loop[i + 1]});
    return;
  }
  normal.normalize();
  const Eigen::Vector3d e1 = normal.unitOrthogonal();
  const Eigen::Vector3d e2 = normal.cross(e1);
  // The loop's points in the plane, once, beside `left`.
  std::vector<Eigen::Vector2d> flat(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = x[static_cast<size_t>(loop[i])];
    flat[i] = Eigen::Vector2d(p.dot(e1), p.dot(e2));
  }
  const auto cross = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
  };
  // Only a corner that is not convex can lie inside a convex corner's triangle: the test of an ear
  // looks at those (flagged, kept up to date for the two corners next to each ear cut).
  const auto convex_at = [&](size_t i, size_t m) {
    const Eigen::Vector2d& a = flat[(i + m - 1) % m];
    const Eigen::Vector2d& b = flat[i];
    const Eigen::Vector2d& c = flat[(i + 1) % m];
    return cross(a, b, c) > 1e-9 * (b - a).norm() * (c - b).norm();
  };
  std::vector<char> convex(n);
  for (size_t i = 0; i < n; ++i) convex[i] = convex_at(i, n) ? 1 : 0;
  size_t from = 0;  // the search goes on where the last ear was cut
  while (left.size() > 3) {
    const size_t m = left.size();
    size_t ear = m;
    for (size_t k = 0; k < m && ear == m; ++k) {
      const size_t i = (from + k) % m;
      if (convex[i] == 0) continue;  // reflex or flat
      const Eigen::Vector2d& a = flat[(i + m - 1) % m];
      const Eigen::Vector2d& b = flat[i];
      const Eigen::Vector2d& c = flat[(i + 1) % m];
      if (m > 3 && edge_exists(left[(i + 1) % m], left[(i + m - 1) % m])) continue;  // a diagonal the mesh has
      bool empty = true;
      for (size_t j = 0; j < m && empty; ++j) {
        if (convex[j] != 0 || j == i || j == (i + m - 1) % m || j == (i + 1) % m) continue;
        const Eigen::Vector2d& p = flat[j];
        empty = !(cross(a, b, p) > 0.0 && cross(b, c, p) > 0.0 && cross(c, a, p) > 0.0);
      }
      if (empty) ear = i;
    }
    // No clean ear (a degenerate loop): cut one anyway, the topology stays closed; one whose
    // diagonal the mesh lacks, so that no edge gets four triangles (cutting the first corner along a
    // surface edge made the complete-cut frog non-manifold in 4 frames under baseline x86-64).
    for (size_t i = 0; i < m && ear == m; ++i) {
      if (!edge_exists(left[(i + 1) % m], left[(i + m - 1) % m])) ear = i;
    }
    if (ear == m) ear = 0;
    triangles.push_back({left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]});
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(ear));
    flat.erase(flat.begin() + static_cast<std::ptrdiff_t>(ear));
    convex.erase(convex.begin() + static_cast<std::ptrdiff_t>(ear));
    const size_t before = (ear + m - 2) % (m - 1), after = ear % (m - 1);
    convex[before] = convex_at(before, m - 1) ? 1 : 0;
    convex[after] = convex_at(after, m - 1) ? 1 : 0;
    from = after;
  }
  triangles.push_back({left[0], left[1], left[2]});
}

// The border loops of a split surface from its directed edges at split points (a border edge has
// no twin), each in the order its cap runs them (against the skin).
std::vector<std::vector<int>> border_loops(const std::unordered_map<long long, int>& directed) {
  std::vector<std::pair<int, int>> next;  // border edges u -> v, sorted
  for (const auto& [edge, uses] : directed) {
    const auto u = static_cast<int>(edge >> 32), v = static_cast<int>(edge & 0xffffffffLL);
    if (!directed.contains(directed_key(v, u))) next.emplace_back(u, v);
  }
  std::sort(next.begin(), next.end());
  std::vector<char> used(next.size(), 0);
  // The first unused border edge from `at` (next.size(): none).
  const auto from = [&](int at) {
    for (auto i =
             static_cast<size_t>(std::lower_bound(next.begin(), next.end(), std::pair{at, INT_MIN}) - next.begin());
         i < next.size() && next[i].first == at; ++i) {
      if (used[i] == 0) return i;
    }
    return next.size();
  };
  std::vector<std::vector<int>> loops;
  for (size_t first = 0; first < next.size(); ++first) {
    if (used[first] != 0) continue;
    std::vector<int> loop;
    const int start = next[first].first;
    int at = start;
    while (true) {
      const size_t i = from(at);
      if (i == next.size()) break;
      loop.push_back(at);
      at = next[i].second;
      used[i] = 1;
      if (at == start) break;
    }
    std::reverse(loop.begin(), loop.end());
    loops.push_back(std::move(loop));
  }
  return loops;
}

// A loop's points' cuts (-1: a surface vertex, a crack tip). Where two cuts meet on the surface the
// points next to the junction may be split by either, so a run shorter than JUNCTION_RUN points
// between two other runs takes a neighbour's cut (the longer's); a tip between two runs of one cut
// (a slit's) stays.
std::vector<int> junction_smoothed(std::vector<int> label) {
  constexpr size_t JUNCTION_RUN = 4;
  const size_t n = label.size();
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t i = 0; i < n && !changed; ++i) {
      if (label[(i + n - 1) % n] == label[i]) continue;  // not a run's start
      size_t length = 1;
      while (length < n && label[(i + length) % n] == label[i]) ++length;
      if (length >= JUNCTION_RUN || length == n) continue;
      const int before = label[(i + n - 1) % n], after = label[(i + length) % n];
      if (label[i] < 0 && before == after) continue;  // a slit's tip
      if (before < 0 && after < 0) continue;
      size_t before_length = 1, after_length = 1;
      while (before_length < n && label[(i + n - 1 - before_length) % n] == before) ++before_length;
      while (after_length < n && label[(i + length + after_length) % n] == after) ++after_length;
      const int into = after < 0 || (before >= 0 && before_length >= after_length) ? before : after;
      for (size_t k = 0; k < length; ++k) label[(i + k) % n] = into;
      changed = true;
    }
  }
  return label;
}

bool flat_within(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x, double tolerance_m) {
  if (loop.empty()) return true;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const int q : loop) centroid += x[static_cast<size_t>(q)];
  centroid /= static_cast<double>(loop.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int q : loop) {
    const Eigen::Vector3d d = x[static_cast<size_t>(q)] - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::Vector3d normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  return std::all_of(loop.begin(), loop.end(), [&](int q) {
    return std::abs((x[static_cast<size_t>(q)] - centroid).dot(normal)) <= tolerance_m;
  });
}

namespace {

// Running sums of a loop's points and their outer products, for the least-squares plane of any run.
struct LoopMoments {
  std::vector<Eigen::Vector3d> sum;  // of points [0, k)
  std::vector<Eigen::Matrix3d> outer;

  LoopMoments(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x)
      : sum(loop.size() + 1, Eigen::Vector3d::Zero()), outer(loop.size() + 1, Eigen::Matrix3d::Zero()) {
    for (size_t k = 0; k < loop.size(); ++k) {
      const Eigen::Vector3d& p = x[static_cast<size_t>(loop[k])];
      sum[k + 1] = sum[k] + p;
      outer[k + 1] = outer[k] + p * p.transpose();
    }
  }
  // The sum of the squared distances of the points [first, end) (or all but them: `complement`) from
  // their least-squares plane: at most count * (the largest distance)^2, and never smaller for more
  // points.
  [[nodiscard]] double squares_off_plane(size_t first, size_t end, bool complement) const {
    Eigen::Vector3d s = sum[end] - sum[first];
    Eigen::Matrix3d o = outer[end] - outer[first];
    double count = static_cast<double>(end - first);
    if (complement) {
      s = sum.back() - s;
      o = outer.back() - o;
      count = static_cast<double>(sum.size() - 1) - count;
    }
    const Eigen::Matrix3d scatter = o - s * s.transpose() / count;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(scatter, Eigen::EigenvaluesOnly);  // closed form, for the many runs tried
    return std::max(solver.eigenvalues()(0), 0.0);
  }
};

}  // namespace

bool split_in_two_flat(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
                       std::vector<std::vector<int>>& flat, const std::function<bool(int, int)>& edge_exists) {
  const size_t n = loop.size();
  if (n > MAX_SPLIT_HOLE_POINTS) return false;
  const LoopMoments moments(loop, x);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j + 2 <= n + i && j < n; ++j) {
      // The halves: points i..j and j..i (wrapping), each with the chord (i, j) as an edge. Once the
      // first half's squares exceed what n points within FLAT_HOLE_M can make, no longer one is flat.
      constexpr double FLAT_SQUARE_M2 = FLAT_HOLE_M * FLAT_HOLE_M;
      const double first_squares = moments.squares_off_plane(i, j + 1, false);
      if (first_squares > static_cast<double>(n) * FLAT_SQUARE_M2) break;
      if (first_squares > static_cast<double>(j + 1 - i) * FLAT_SQUARE_M2 ||
          moments.squares_off_plane(i + 1, j, true) > static_cast<double>(n - (j - i - 1)) * FLAT_SQUARE_M2 ||
          (edge_exists && edge_exists(loop[i], loop[j]))) {  // its four triangles would share the chord
        continue;
      }
      std::vector<int> first(loop.begin() + static_cast<long>(i), loop.begin() + static_cast<long>(j) + 1);
      std::vector<int> second(loop.begin() + static_cast<long>(j), loop.end());
      second.insert(second.end(), loop.begin(), loop.begin() + static_cast<long>(i) + 1);
      if (!flat_within(first, x, FLAT_HOLE_M) || !flat_within(second, x, FLAT_HOLE_M)) continue;
      flat.push_back(std::move(first));
      flat.push_back(std::move(second));
      return true;
    }
  }
  return false;
}

namespace {

// A maximal run of a hole's points on one cut (-1: on none, the line points of caps made before).
struct CutRun {
  int cut;
  std::vector<int> points;  // in the hole's order
};

// Joins run `i` and the one after it (cyclic) into one on `cut`.
void join_with_next(std::vector<CutRun>& runs, size_t i, int cut) {
  const size_t next = (i + 1) % runs.size();
  runs[i].cut = cut;
  if (next == 0) {  // the last run before the first: the first's points come after
    runs[0].points.insert(runs[0].points.begin(), runs[i].points.begin(), runs[i].points.end());
    runs[0].cut = cut;
    runs.pop_back();
    return;
  }
  runs[i].points.insert(runs[i].points.end(), runs[next].points.begin(), runs[next].points.end());
  runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(next));
}

// The runs made whole: neighbours on one cut joined; a run on no cut, or of at most SHORT_RUN points,
// between two runs of one cut joins them (a junction line already capped on its other side, a switch
// a few points long); a run on no cut between two cuts joins the run before it.
void normalize_runs(std::vector<CutRun>& runs) {
  constexpr size_t SHORT_RUN = 2;
  for (bool changed = true; changed && runs.size() > 1;) {
    changed = false;
    for (size_t i = 0; i < runs.size() && runs.size() > 1 && !changed; ++i) {
      const size_t next = (i + 1) % runs.size();
      if (runs[i].cut == runs[next].cut) {
        join_with_next(runs, i, runs[i].cut);
        changed = true;
      }
    }
    for (size_t i = 0; i < runs.size() && runs.size() > 2 && !changed; ++i) {
      const size_t before = (i + runs.size() - 1) % runs.size(), after = (i + 1) % runs.size();
      const CutRun& run = runs[i];
      if ((run.cut < 0 || run.points.size() <= SHORT_RUN) && runs[before].cut >= 0 &&
          runs[before].cut == runs[after].cut) {
        join_with_next(runs, before, runs[before].cut);  // the run after joins it next (same cut)
        changed = true;
      }
    }
    for (size_t i = 0; i < runs.size() && runs.size() > 1 && !changed; ++i) {
      if (runs[i].cut >= 0) continue;
      const size_t before = (i + runs.size() - 1) % runs.size();
      join_with_next(runs, before, runs[before].cut);
      changed = true;
    }
  }
}

}  // namespace

bool peel_by_cuts(const std::vector<int>& loop, const std::vector<Eigen::Vector3d>& x,
                  const std::function<int(int)>& cut_of, const std::function<std::vector<int>(int, int)>& line_points,
                  std::vector<std::vector<int>>& faces, PeelOrder order) {
  const size_t n = loop.size();
  if (n < 3) return false;
  size_t start = 0;  // a change of cut, if there is one
  while (start < n && cut_of(loop[start]) == cut_of(loop[(start + n - 1) % n])) ++start;
  std::vector<CutRun> runs;
  for (size_t k = 0; k < n; ++k) {
    const int point = loop[(start + k) % n];
    if (runs.empty() || runs.back().cut != cut_of(point)) runs.push_back(CutRun{cut_of(point), {}});
    runs.back().points.push_back(point);
  }
  normalize_runs(runs);
  std::vector<std::vector<int>> peeled;  // appended to `faces` only if the whole hole is peeled
  while (runs.size() > 1) {
    // The run `order` names (by default the one whose ends lie nearest each other): its face closed by
    // the line between its ends.
    size_t best = runs.size();
    double least = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < runs.size(); ++i) {
      const std::vector<int>& points = runs[i].points;
      if (points.size() < 2) continue;
      const double gap = (x[static_cast<size_t>(points.front())] - x[static_cast<size_t>(points.back())]).norm();
      const auto length = static_cast<double>(points.size());
      const double rank = order == PeelOrder::nearest_ends    ? gap
                          : order == PeelOrder::farthest_ends ? -gap
                          : order == PeelOrder::longest_run   ? -length
                                                              : length;
      if (rank < least) {
        least = rank;
        best = i;
      }
    }
    if (best == runs.size()) return false;
    const int first = runs[best].points.front(), last = runs[best].points.back();
    std::vector<int> line = line_points(last, first);
    std::vector<int> face = std::move(runs[best].points);
    face.insert(face.end(), line.begin(), line.end());
    peeled.push_back(std::move(face));
    // What is left runs the line the other way, its ends kept.
    std::vector<int> rest{first};
    rest.insert(rest.end(), line.rbegin(), line.rend());
    rest.push_back(last);
    runs[best] = CutRun{-1, std::move(rest)};
    normalize_runs(runs);
  }
  peeled.push_back(std::move(runs.front().points));
  for (std::vector<int>& face : peeled) faces.push_back(std::move(face));
  return true;
}

FlatHoles flat_holes(const std::unordered_map<long long, int>& directed, const std::vector<Eigen::Vector3d>& x,
                     const std::function<int(int)>& part_of, const std::function<int(int)>& cut_of,
                     const std::function<std::vector<int>(int, int)>& line_points) {
  FlatHoles holes;
  for (std::vector<int>& loop : border_loops(directed)) {
    const bool closed = loop.size() >= 3 && directed.contains(directed_key(loop.front(), loop.back()));
    const int part = closed ? part_of(loop.front()) : -1;
    const bool one_part = closed && std::all_of(loop.begin(), loop.end(), [&](int q) { return part_of(q) == part; });
    const auto edge_exists = [&directed](int u, int v) {
      return directed.contains(directed_key(u, v)) || directed.contains(directed_key(v, u));
    };
    const size_t first_face = holes.flat.size();
    if (one_part && flat_within(loop, x, FLAT_HOLE_M)) {
      holes.flat.push_back(std::move(loop));
      continue;
    }
    if (one_part && split_in_two_flat(loop, x, holes.flat, edge_exists)) continue;
    if (one_part && line_points && peel_by_cuts(loop, x, cut_of, line_points, holes.flat)) {
      holes.peeled.push_back({part, first_face, holes.flat.size(), std::move(loop)});
      continue;
    }
    ++holes.others;
    holes.open_parts.push_back(one_part ? part : -1);
  }
  return holes;
}

// A chain whose points all ride on uncut tets faces neither side of its cut (0): a switch of it alone
// under its key joins the one lone switch whose key differs only there.
void merge_unfacing_switches(std::map<std::array<int, 5>, std::vector<size_t>>& switches) {
  for (auto it = switches.begin(); it != switches.end();) {
    const std::array<int, 5> key = it->first;
    if (it->second.size() != 1 || (key[3] != 0 && key[4] != 0)) {
      ++it;
      continue;
    }
    std::vector<size_t>* into = nullptr;
    int found = 0;
    for (const size_t slot : {size_t{3}, size_t{4}}) {
      if (key[slot] != 0) continue;
      for (const int side : {-1, 1}) {
        std::array<int, 5> other = key;
        other[slot] = side;
        const auto match = switches.find(other);
        if (match == switches.end() || match->second.size() != 1) continue;
        into = &match->second;
        ++found;
      }
    }
    if (found != 1) {
      ++it;
      continue;
    }
    into->push_back(it->second[0]);
    it = switches.erase(it);
  }
}

void point_shells(const std::vector<std::array<int, 3>>& triangles, size_t point_count, std::vector<int>& root,
                  std::vector<int>& size) {
  root.resize(point_count);
  std::iota(root.begin(), root.end(), 0);
  size.assign(point_count, 1);
  const auto unite = [&](int a, int b) {
    a = find_root(root, a);
    b = find_root(root, b);
    if (a == b) return;
    if (size[static_cast<size_t>(a)] < size[static_cast<size_t>(b)]) std::swap(a, b);
    root[static_cast<size_t>(b)] = a;
    size[static_cast<size_t>(a)] += size[static_cast<size_t>(b)];
  };
  for (const auto& t : triangles) {
    unite(t[0], t[1]);
    unite(t[1], t[2]);
  }
  // Each point's root at once: the callers read it for every triangle (82k on the organ's surface).
  for (size_t i = 0; i < root.size(); ++i) root[i] = find_root(root, static_cast<int>(i));
}

size_t drop_bubbles(std::vector<std::array<int, 3>>& triangles, size_t first_cap, const std::vector<Eigen::Vector3d>& x,
                    BubbleScratch& scratch) {
  point_shells(triangles, x.size(), scratch.parent, scratch.size);
  const std::vector<int>& parent = scratch.parent;
  const auto root = [&parent](int v) { return parent[static_cast<size_t>(v)]; };
  // Per shell holding a cap (by its root point): its volume about that point (closed: any point will
  // do); others are not candidates.
  constexpr signed char NOT_A_CANDIDATE = 0, SMALL = 1, OPEN = 2;
  std::vector<signed char>& state = scratch.state;
  std::vector<double>& volume_m3 = scratch.volume_m3;
  state.assign(x.size(), NOT_A_CANDIDATE);
  volume_m3.assign(x.size(), 0.0);
  for (size_t t = first_cap; t < triangles.size(); ++t) state[static_cast<size_t>(root(triangles[t][0]))] = SMALL;
  std::vector<size_t>& shell_of = scratch.shell_of;
  shell_of.resize(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto shell = static_cast<size_t>(root(triangles[t][0]));
    shell_of[t] = shell;
    if (state[shell] == NOT_A_CANDIDATE) continue;
    const Eigen::Vector3d& o = x[shell];
    const auto& [i, j, k] = triangles[t];
    const Eigen::Vector3d a = x[static_cast<size_t>(i)] - o, b = x[static_cast<size_t>(j)] - o,
                          c = x[static_cast<size_t>(k)] - o;
    volume_m3[shell] += a.dot(b.cross(c)) / 6.0;
  }
  // The small ones, if closed (every edge once each way).
  std::unordered_map<long long, int>& directed = scratch.directed;
  directed.clear();
  for (size_t t = 0; t < triangles.size(); ++t) {
    const size_t shell = shell_of[t];
    if (state[shell] == NOT_A_CANDIDATE) continue;
    if (std::abs(volume_m3[shell]) >= BUBBLE_M3) {
      state[shell] = NOT_A_CANDIDATE;
      continue;
    }
    for (size_t c = 0; c < 3; ++c) ++directed[directed_key(triangles[t][c], triangles[t][(c + 1) % 3])];
  }
  if (directed.empty()) return triangles.size() - first_cap;
  for (const auto& [key, uses] : directed) {
    const auto from = static_cast<int>(key >> 32), to = static_cast<int>(key & 0xffffffffLL);
    const auto twin = directed.find(directed_key(to, from));
    if (uses != 1 || twin == directed.end() || twin->second != 1) state[static_cast<size_t>(root(from))] = OPEN;
  }
  size_t kept_caps = 0, out = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (state[shell_of[t]] == SMALL) continue;  // a closed small shell: a bubble
    if (t >= first_cap) ++kept_caps;
    triangles[out++] = triangles[t];
  }
  triangles.resize(out);
  return kept_caps;
}

}  // namespace tissue::cut_render_detail
