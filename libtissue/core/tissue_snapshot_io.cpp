// TissueSnapshot <-> bytes (see tissue_snapshot_io.hpp).
#include "core/tissue_snapshot_io.hpp"

#include "serial/byte_stream.hpp"

#include <array>
#include <cmath>
#include <string>

namespace tissue {
namespace {

constexpr std::uint64_t MAGIC = 0x31305353'49535354ULL;  // "TSSISS01" read as little-endian bytes
// 2: PointSpring::tangent_fraction; 3: the cuts' enrichment offsets; 4: the applied tool position;
// 5: several cuts per tet (pieces' offsets and rotations, the cuts' smallest fraction, cut counts);
// 7: a ghost's unknown is its copy's displacement, not a difference from u (issue 40): the same
// fields, other meanings; 8: the cutter's per-vertex sides, distances and the blade's plane of the
// open session (issue 41); 9: each cut's blade normal (TetCut::blade_normal); 10: how far the blade
// had turned when each tet was cut and each edge crossed (a spiral cuts a tet once per turn);
// 12: the contact spring's direction and constant force, the contact's sticking and friction (issue 42);
// 13: a pad probe's springs and its samples pressed (issue 42); 14: each tet's and piece's turn
// before (the rotations' warm start extrapolated, issue 40); 15: copies of fixed vertices that touch held
// material are held, without unknowns (issue 41): a state saved before has more unknowns
constexpr std::uint32_t VERSION = 15;

// The core's Eigen types and cut records on top of the shared byte stream.
class Writer : public serial::ByteWriter {
 public:
  using serial::ByteWriter::put;
  void put(const Eigen::VectorXd& v) {
    put(static_cast<std::uint64_t>(v.size()));
    for (Eigen::Index k = 0; k < v.size(); ++k) put(v(k));
  }
  void put(const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) put(v(k));
  }
  void put(const Eigen::Matrix3d& m) {
    for (int k = 0; k < 9; ++k) put(m(k));
  }
  void put(const Eigen::Quaterniond& q) {
    for (int k = 0; k < 4; ++k) put(q.coeffs()(k));
  }
  template <class T>
  void put_all(const std::vector<T>& values) {
    put(static_cast<std::uint64_t>(values.size()));
    for (const T& value : values) put_item(value);
  }

  template <class T>
  void put_item(const T& value) {
    put(value);
  }
  template <class T, size_t N>
  void put_item(const std::array<T, N>& values) {
    for (const T& value : values) put(value);
  }
  void put_item(const TetCut& cut) {
    put(cut.tet);
    put(cut.cut_id);
    put_item(cut.side);
    put(cut.volume_fraction_above);
    put_item(cut.edge_ratio);
    put(cut.min_volume_fraction);
    put(cut.blade_normal);
  }
  void put_item(const ParkedRows& parked) {
    put(parked.after_batch);
    put_all(parked.rows);
  }
  template <class T>
  void put_item(const std::vector<T>& values) {
    put_all(values);
  }
};

class Reader : public serial::ByteReader {
 public:
  using serial::ByteReader::ByteReader;
  using serial::ByteReader::get;

  // Every number a tissue keeps is finite: a state holding a NaN or an infinity is refused here,
  // not by the step after it is restored (found by fuzzing, issue 44).
  double real() {
    const auto x = get<double>();
    if (!std::isfinite(x)) fail("a non-finite number");
    return x;
  }
  void get(double& x) { x = real(); }
  void get(Eigen::VectorXd& v) {
    v.resize(static_cast<Eigen::Index>(count(sizeof(double))));
    for (Eigen::Index k = 0; k < v.size(); ++k) v(k) = real();
  }
  void get(Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) v(k) = real();
  }
  void get(Eigen::Matrix3d& m) {
    for (int k = 0; k < 9; ++k) m(k) = real();
  }
  void get(Eigen::Quaterniond& q) {
    for (int k = 0; k < 4; ++k) q.coeffs()(k) = real();
  }
  template <class T, size_t N>
  void get(std::array<T, N>& values) {
    for (T& value : values) get(value);
  }
  void get(TetCut& cut) {
    get(cut.tet);
    get(cut.cut_id);
    get(cut.side);
    get(cut.volume_fraction_above);
    get(cut.edge_ratio);
    get(cut.min_volume_fraction);
    get(cut.blade_normal);
  }
  void get(ParkedRows& parked) {
    get(parked.after_batch);
    get_all(parked.rows, 4);
  }
  template <class T>
  void get(std::vector<T>& values) {
    get_all(values, 8);
  }
  template <class T>
  void get_all(std::vector<T>& values, size_t item_bytes) {
    values.resize(count(item_bytes));
    for (T& value : values) get(value);
  }
};

void put_tool(Writer& w, const ToolPose& tool) {
  w.put(tool.tip_position_m);
  w.put(tool.orientation);
  w.put(static_cast<std::int32_t>(tool.mode));
}

ToolPose get_tool(Reader& r) {
  ToolPose tool;
  r.get(tool.tip_position_m);
  r.get(tool.orientation);
  const auto mode = r.get<std::int32_t>();
  if (mode < 0 || mode > 2) serial::ByteReader::fail("bad tool mode " + std::to_string(mode));
  tool.mode = static_cast<ToolMode>(mode);
  return tool;
}

void put_spring(Writer& w, const PointSpring& spring) {
  w.put_item(spring.vertices);
  w.put(spring.weights);
  w.put(spring.target_m);
  w.put(spring.stiffness_n_per_m);
  w.put(spring.tangent_fraction);
  w.put(spring.direction);
  w.put(spring.constant_force_on_body_n);
}

PointSpring get_spring(Reader& r) {
  PointSpring spring;
  r.get(spring.vertices);
  r.get(spring.weights);
  r.get(spring.target_m);
  r.get(spring.stiffness_n_per_m);
  r.get(spring.tangent_fraction);
  r.get(spring.direction);
  r.get(spring.constant_force_on_body_n);
  return spring;
}

// Bytes of a spring as put_spring writes it: 3 ints and 14 doubles.
constexpr size_t SPRING_BYTES = 3 * sizeof(std::int32_t) + 14 * sizeof(double);

}  // namespace

std::vector<std::uint8_t> serialize_snapshot(const TissueSnapshot& s) {
  Writer w;
  w.put(MAGIC);
  w.put(VERSION);
  w.put(s.model_fingerprint);
  w.put_all(s.cuts);
  w.put_all(s.cut_batch_ends);
  w.put_all(s.cut_offsets);
  w.put_all(s.parked);
  w.put(s.steps_since_park_check);
  w.put(s.dynamics.displacement_m);
  w.put(s.dynamics.velocity_m_per_s);
  w.put(s.dynamics.time_s);
  w.put_all(s.rotations.tets);
  w.put_all(s.rotations.tet_warm_starts);
  w.put_all(s.rotations.pieces);
  w.put_all(s.rotations.piece_warm_starts);
  w.put_all(s.rotations.tet_turns_before);
  w.put_all(s.rotations.piece_turns_before);
  w.put(s.integrator_state);
  const VolumeCutter::SessionState& c = s.cutter;
  w.put(static_cast<std::uint8_t>(c.cutting));
  w.put(c.cut_id);
  w.put_all(c.tet_cut_session);
  w.put_all(c.tet_cut_turn_rad);
  w.put_all(c.tet_ignored_session);
  w.put_all(c.tet_cut_count);
  w.put_all(c.tet_cut_above);
  w.put_all(c.edge_session);
  w.put_all(c.edge_ratio);
  w.put_all(c.edge_turn_rad);
  w.put_all(c.vertex_session);
  w.put_all(c.vertex_side);
  w.put_all(c.vertex_distance_m);
  w.put_all(c.vertex_turn_rad);
  w.put_all(c.watched);
  w.put(c.idle_steps);
  w.put(c.record_epoch);
  w.put(c.turn_rad);
  w.put_all(c.session_vertices);
  for (const Eigen::Vector3d& p : c.plane) w.put(p);
  w.put(static_cast<std::uint8_t>(c.plane_valid));
  w.put_all(c.active);
  w.put(static_cast<std::uint8_t>(s.contact.in_contact));
  w.put(s.contact.proxy.triangle);
  w.put(s.contact.proxy.barycentric);
  w.put(s.contact.proxy_position_m);
  w.put(s.contact.normal);
  w.put(s.contact.hip_m);
  w.put(s.contact.depth_m);
  w.put(static_cast<std::uint8_t>(s.contact.sticking));
  w.put(s.contact.friction_on_body_n);
  w.put(s.contact.pad_pressed);
  w.put(static_cast<std::uint8_t>(s.point_spring.has_value()));
  if (s.point_spring) put_spring(w, *s.point_spring);
  w.put(static_cast<std::uint64_t>(s.pad_springs.size()));
  for (const PointSpring& spring : s.pad_springs) put_spring(w, spring);
  put_tool(w, s.tool);
  put_tool(w, s.previous_tool);
  w.put(s.applied_tool_position_m);
  const ContactOutput& o = s.contact_output;
  w.put(static_cast<std::uint8_t>(o.active));
  w.put(o.point_m);
  w.put(o.normal);
  w.put(o.force_on_tool_n);
  w.put(o.stiffness_n_per_m);
  w.put(o.penetration_depth_m);
  w.put(s.steps_since_stiffness);
  w.put(static_cast<std::uint8_t>(s.pending_stiffness));
  w.put(s.pending_stiffness_n_per_m);
  return w.take();
}

namespace {

TissueSnapshot read_snapshot(std::span<const std::uint8_t> bytes) {
  Reader r(bytes);
  if (r.get<std::uint64_t>() != MAGIC) serial::ByteReader::fail("not a tissue state (bad magic)");
  if (const auto version = r.get<std::uint32_t>(); version != VERSION) {
    serial::ByteReader::fail("version " + std::to_string(version) + " is not " + std::to_string(VERSION));
  }
  TissueSnapshot s;
  r.get(s.model_fingerprint);
  r.get_all(s.cuts, 4 + 4 + 4 + 8 + 48 + 8 + 24);
  r.get_all(s.cut_batch_ends, 4);
  r.get_all(s.cut_offsets, 8);
  r.get_all(s.parked, 4 + 8);
  r.get(s.steps_since_park_check);
  r.get(s.dynamics.displacement_m);
  r.get(s.dynamics.velocity_m_per_s);
  r.get(s.dynamics.time_s);
  r.get_all(s.rotations.tets, 72);
  r.get_all(s.rotations.tet_warm_starts, 32);
  r.get_all(s.rotations.pieces, 72);
  r.get_all(s.rotations.piece_warm_starts, 32);
  r.get_all(s.rotations.tet_turns_before, 32);
  r.get_all(s.rotations.piece_turns_before, 32);
  r.get(s.integrator_state);
  VolumeCutter::SessionState& c = s.cutter;
  c.cutting = r.get_bool();
  r.get(c.cut_id);
  r.get_all(c.tet_cut_session, 4);
  r.get_all(c.tet_cut_turn_rad, 8);
  r.get_all(c.tet_ignored_session, 4);
  r.get_all(c.tet_cut_count, 1);
  r.get_all(c.tet_cut_above, 1);
  r.get_all(c.edge_session, 4);
  r.get_all(c.edge_ratio, 8);
  r.get_all(c.edge_turn_rad, 8);
  r.get_all(c.vertex_session, 4);
  r.get_all(c.vertex_side, 1);
  r.get_all(c.vertex_distance_m, 8);
  r.get_all(c.vertex_turn_rad, 8);
  r.get_all(c.watched, 4);
  r.get(c.idle_steps);
  r.get(c.record_epoch);
  r.get(c.turn_rad);
  r.get_all(c.session_vertices, 4);
  for (Eigen::Vector3d& p : c.plane) r.get(p);
  c.plane_valid = r.get_bool();
  r.get_all(c.active, 4);
  s.contact.in_contact = r.get_bool();
  r.get(s.contact.proxy.triangle);
  r.get(s.contact.proxy.barycentric);
  r.get(s.contact.proxy_position_m);
  r.get(s.contact.normal);
  r.get(s.contact.hip_m);
  r.get(s.contact.depth_m);
  s.contact.sticking = r.get_bool();
  r.get(s.contact.friction_on_body_n);
  r.get(s.contact.pad_pressed);
  if ((s.contact.pad_pressed >> PAD_SAMPLES) != 0) serial::ByteReader::fail("a pad sample beyond the pad's");
  if (r.get_bool()) s.point_spring = get_spring(r);
  s.pad_springs.resize(r.count(SPRING_BYTES));
  for (PointSpring& spring : s.pad_springs) spring = get_spring(r);
  s.tool = get_tool(r);
  s.previous_tool = get_tool(r);
  r.get(s.applied_tool_position_m);
  ContactOutput& o = s.contact_output;
  o.active = r.get_bool();
  r.get(o.point_m);
  r.get(o.normal);
  r.get(o.force_on_tool_n);
  r.get(o.stiffness_n_per_m);
  r.get(o.penetration_depth_m);
  r.get(s.steps_since_stiffness);
  const auto pending = r.get<std::uint8_t>();
  if (pending > static_cast<std::uint8_t>(TissueSnapshot::PendingStiffness::ready)) {
    serial::ByteReader::fail("pending contact stiffness state " + std::to_string(pending) + " is not 0, 1 or 2");
  }
  s.pending_stiffness = static_cast<TissueSnapshot::PendingStiffness>(pending);
  r.get(s.pending_stiffness_n_per_m);
  r.finish();
  return s;
}

}  // namespace

TissueSnapshot deserialize_snapshot(std::span<const std::uint8_t> bytes) {
  try {
    return read_snapshot(bytes);
  } catch (const serial::FormatError& error) {
    throw StateError(error.what());
  }
}

}  // namespace tissue
