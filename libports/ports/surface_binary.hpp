// The Tissue FMU's Binary surface outputs (issue 22), written once: the FMU encodes them, the host
// and the tests decode them. Little-endian (the x86-64 machines the FMUs are built for), no padding.
// Never truncated: the arrays grow with the surface, so an importer always gets the whole of it.
//
// surface.mesh (any importer: the drawn surface as it is now)
//   u32 magic "TSM1" | u32 version 1 | u64 V | u64 T | u64 C (the last C triangles are cut faces)
//   f64[3V] positions [m] | u32[3T] triangles (0-based, counter-clockwise seen from outside)
// surface.embedding (changes with surface.revision: the points as weighted sums of nodes)
//   u32 magic "TSE1" | u32 version 1 | u64 revision | u64 N nodes | u64 P points | u64 T | u64 C
//   u32[4P] nodes of each point | f64[4P] their weights | u32[3T] triangles (rows of the points)
// surface.nodes (every step: the nodes' positions; point i = sum_k w_ik node_{n_ik})
//   u32 magic "TSN1" | u32 version 1 | u64 revision | u64 N | f64[3N] positions [m]
// A viewer takes the embedding once per revision and the nodes every frame (N is the coarse mesh's
// size; P the fine surface's). Header only, plain C++20.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace tissue::ports {

inline constexpr std::uint32_t SURFACE_MESH_MAGIC = 0x314D5354;       // "TSM1"
inline constexpr std::uint32_t SURFACE_EMBEDDING_MAGIC = 0x31455354;  // "TSE1"
inline constexpr std::uint32_t SURFACE_NODES_MAGIC = 0x314E5354;      // "TSN1"
inline constexpr std::uint32_t SURFACE_BINARY_VERSION = 1;

struct SurfaceMesh {
  std::vector<double> positions_m;      ///< 3 per vertex
  std::vector<std::uint32_t> triangles;  ///< 3 per triangle
  std::uint64_t cut_triangle_count = 0;
};

struct SurfaceEmbedding {
  std::uint64_t revision = 0;
  std::uint64_t node_count = 0;
  std::vector<std::uint32_t> point_nodes;  ///< 4 per point
  std::vector<double> point_weights;       ///< 4 per point
  std::vector<std::uint32_t> triangles;    ///< 3 per triangle, rows of the points
  std::uint64_t cut_triangle_count = 0;
  [[nodiscard]] std::size_t point_count() const { return point_nodes.size() / 4; }
};

struct SurfaceNodes {
  std::uint64_t revision = 0;
  std::vector<double> positions_m;  ///< 3 per node
};

/// A Binary surface output that is not what its layout says.
class SurfaceBinaryError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace surface_binary_detail {

class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& out) : m_out(out) { m_out.clear(); }
  template <class T>
  void put(T value) {
    append(&value, sizeof(T));
  }
  template <class T>
  void put_all(const std::vector<T>& values) {
    append(values.data(), values.size() * sizeof(T));
  }

 private:
  void append(const void* data, std::size_t size) {
    if (size == 0) return;
    const std::size_t at = m_out.size();
    m_out.resize(at + size);
    std::memcpy(m_out.data() + at, data, size);
  }
  std::vector<std::uint8_t>& m_out;
};

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const char* what) : m_bytes(bytes), m_what(what) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, m_bytes.data() + m_at, sizeof(T));
    m_at += sizeof(T);
    return value;
  }
  /// `count` values of T into `out` (the count checked against the bytes left first).
  template <class T>
  void get_all(std::uint64_t count, std::vector<T>& out) {
    if (count > (m_bytes.size() - m_at) / sizeof(T)) fail("truncated");
    out.resize(static_cast<std::size_t>(count));
    if (count > 0) std::memcpy(out.data(), m_bytes.data() + m_at, out.size() * sizeof(T));
    m_at += out.size() * sizeof(T);
  }
  void header(std::uint32_t magic) {
    if (get<std::uint32_t>() != magic) fail("not this output (wrong magic)");
    if (get<std::uint32_t>() != SURFACE_BINARY_VERSION) fail("unknown version");
  }
  void finish() const {
    if (m_at != m_bytes.size()) fail("trailing bytes");
  }
  [[noreturn]] void fail(const std::string& why) const { throw SurfaceBinaryError(std::string(m_what) + ": " + why); }

 private:
  void need(std::size_t n) const {
    if (n > m_bytes.size() - m_at) fail("truncated");
  }
  std::span<const std::uint8_t> m_bytes;
  std::size_t m_at = 0;
  const char* m_what;
};

inline void check_triangles(const Reader& reader, const std::vector<std::uint32_t>& triangles, std::uint64_t rows,
                            std::uint64_t cut_triangles) {
  for (const std::uint32_t v : triangles) {
    if (v >= rows) reader.fail("a triangle names row " + std::to_string(v) + " of " + std::to_string(rows));
  }
  if (cut_triangles > triangles.size() / 3) reader.fail("more cut triangles than triangles");
}

inline void check_finite(const Reader& reader, const std::vector<double>& values, const char* what) {
  for (const double x : values) {
    if (!std::isfinite(x)) reader.fail(std::string("a non-finite ") + what);
  }
}

}  // namespace surface_binary_detail

inline void encode(const SurfaceMesh& mesh, std::vector<std::uint8_t>& out) {
  surface_binary_detail::Writer w(out);
  w.put(SURFACE_MESH_MAGIC);
  w.put(SURFACE_BINARY_VERSION);
  w.put(static_cast<std::uint64_t>(mesh.positions_m.size() / 3));
  w.put(static_cast<std::uint64_t>(mesh.triangles.size() / 3));
  w.put(mesh.cut_triangle_count);
  w.put_all(mesh.positions_m);
  w.put_all(mesh.triangles);
}

inline void encode(const SurfaceEmbedding& embedding, std::vector<std::uint8_t>& out) {
  surface_binary_detail::Writer w(out);
  w.put(SURFACE_EMBEDDING_MAGIC);
  w.put(SURFACE_BINARY_VERSION);
  w.put(embedding.revision);
  w.put(embedding.node_count);
  w.put(static_cast<std::uint64_t>(embedding.point_count()));
  w.put(static_cast<std::uint64_t>(embedding.triangles.size() / 3));
  w.put(embedding.cut_triangle_count);
  w.put_all(embedding.point_nodes);
  w.put_all(embedding.point_weights);
  w.put_all(embedding.triangles);
}

inline void encode(const SurfaceNodes& nodes, std::vector<std::uint8_t>& out) {
  surface_binary_detail::Writer w(out);
  w.put(SURFACE_NODES_MAGIC);
  w.put(SURFACE_BINARY_VERSION);
  w.put(nodes.revision);
  w.put(static_cast<std::uint64_t>(nodes.positions_m.size() / 3));
  w.put_all(nodes.positions_m);
}

/// Each decode throws SurfaceBinaryError unless the bytes are exactly one such output with every
/// index in range and every number finite.
inline void decode(std::span<const std::uint8_t> bytes, SurfaceMesh& mesh) {
  surface_binary_detail::Reader r(bytes, "surface.mesh");
  r.header(SURFACE_MESH_MAGIC);
  const auto vertices = r.get<std::uint64_t>();
  const auto triangles = r.get<std::uint64_t>();
  mesh.cut_triangle_count = r.get<std::uint64_t>();
  if (vertices > bytes.size() || triangles > bytes.size()) r.fail("truncated");
  r.get_all(3 * vertices, mesh.positions_m);
  r.get_all(3 * triangles, mesh.triangles);
  r.finish();
  surface_binary_detail::check_finite(r, mesh.positions_m, "position");
  surface_binary_detail::check_triangles(r, mesh.triangles, vertices, mesh.cut_triangle_count);
}

inline void decode(std::span<const std::uint8_t> bytes, SurfaceEmbedding& embedding) {
  surface_binary_detail::Reader r(bytes, "surface.embedding");
  r.header(SURFACE_EMBEDDING_MAGIC);
  embedding.revision = r.get<std::uint64_t>();
  embedding.node_count = r.get<std::uint64_t>();
  const auto points = r.get<std::uint64_t>();
  const auto triangles = r.get<std::uint64_t>();
  embedding.cut_triangle_count = r.get<std::uint64_t>();
  if (points > bytes.size() || triangles > bytes.size()) r.fail("truncated");
  r.get_all(4 * points, embedding.point_nodes);
  r.get_all(4 * points, embedding.point_weights);
  r.get_all(3 * triangles, embedding.triangles);
  r.finish();
  for (const std::uint32_t n : embedding.point_nodes) {
    if (n >= embedding.node_count) r.fail("a point names node " + std::to_string(n) + " of " + std::to_string(embedding.node_count));
  }
  surface_binary_detail::check_finite(r, embedding.point_weights, "weight");
  surface_binary_detail::check_triangles(r, embedding.triangles, points, embedding.cut_triangle_count);
}

inline void decode(std::span<const std::uint8_t> bytes, SurfaceNodes& nodes) {
  surface_binary_detail::Reader r(bytes, "surface.nodes");
  r.header(SURFACE_NODES_MAGIC);
  nodes.revision = r.get<std::uint64_t>();
  const auto count = r.get<std::uint64_t>();
  if (count > bytes.size()) r.fail("truncated");
  r.get_all(3 * count, nodes.positions_m);
  r.finish();
  surface_binary_detail::check_finite(r, nodes.positions_m, "position");
}

/// The points' positions: point i at sum_k w_ik node_{n_ik} (3 per point into `positions_m`).
/// Throws SurfaceBinaryError when the nodes are not the embedding's (another revision or count).
inline void map_points(const SurfaceEmbedding& embedding, const SurfaceNodes& nodes, std::vector<double>& positions_m) {
  if (nodes.revision != embedding.revision || nodes.positions_m.size() != 3 * embedding.node_count) {
    throw SurfaceBinaryError("surface.nodes (revision " + std::to_string(nodes.revision) +
                             ") are not those of surface.embedding (revision " + std::to_string(embedding.revision) + ")");
  }
  const std::size_t points = embedding.point_count();
  positions_m.resize(3 * points);
  for (std::size_t i = 0; i < points; ++i) {
    double x[3] = {0.0, 0.0, 0.0};
    for (std::size_t k = 0; k < 4; ++k) {
      const double w = embedding.point_weights[4 * i + k];
      const double* node = &nodes.positions_m[3 * static_cast<std::size_t>(embedding.point_nodes[4 * i + k])];
      for (std::size_t c = 0; c < 3; ++c) x[c] += w * node[c];
    }
    for (std::size_t c = 0; c < 3; ++c) positions_m[3 * i + c] = x[c];
  }
}

}  // namespace tissue::ports
