#include "support/state_mutator.hpp"

#include "core/state_error.hpp"
#include "core/tissue_snapshot_io.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <vector>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace tissue::fuzz {

namespace {

constexpr std::size_t TRAILER_BYTES = 16;  // surface_revision, integrator_iterations (u64 each)

struct Found {
  std::size_t length_at = 0;  // offset of the snapshot's u64 length
  TissueSnapshot snapshot;
};

std::optional<Found> find_snapshot(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < TRAILER_BYTES + 8) return std::nullopt;
  for (std::size_t at = 0; at + 8 + TRAILER_BYTES <= bytes.size(); ++at) {
    std::uint64_t length = 0;
    std::memcpy(&length, bytes.data() + at, sizeof(length));
    if (length != bytes.size() - at - 8 - TRAILER_BYTES) continue;
    try {
      return Found{at, deserialize_snapshot(bytes.subspan(at + 8, length))};
    } catch (const StateError&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

double special_double(std::mt19937& rng) {
  static const double values[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                                  -std::numeric_limits<double>::infinity(), 1e300, -1e300, 0.0, -0.0, 5e-324,
                                  1.0, -1.0, 0.5, 2.0};
  return values[rng() % std::size(values)];
}

int special_int(std::mt19937& rng) {
  static const int values[] = {-1, 0, 1, 2, 7, 1000000, std::numeric_limits<int>::max(),
                               std::numeric_limits<int>::min()};
  return values[rng() % std::size(values)];
}

void mutate_vector(Eigen::VectorXd& v, std::mt19937& rng) {
  if (v.size() > 0 && rng() % 3 != 0) {
    v(static_cast<Eigen::Index>(rng() % static_cast<unsigned>(v.size()))) = special_double(rng);
  } else {
    const Eigen::Index sizes[] = {0, v.size() - 1, v.size() + 1, v.size() + 3};
    v.conservativeResize(std::max<Eigen::Index>(0, sizes[rng() % 4]));
  }
}

void mutate_cut(TetCut& cut, std::mt19937& rng) {
  switch (rng() % 7) {
    case 0: cut.tet = special_int(rng); break;
    case 1: cut.cut_id = special_int(rng); break;
    case 2: cut.side[rng() % 4] = static_cast<std::int8_t>(rng()); break;
    case 3: cut.volume_fraction_above = special_double(rng); break;
    case 4: cut.edge_ratio[rng() % 6] = special_double(rng); break;
    case 5: cut.min_volume_fraction = special_double(rng); break;
    default: cut.blade_normal(rng() % 3) = special_double(rng); break;
  }
}

void mutate_cuts(TissueSnapshot& s, std::mt19937& rng) {
  if (s.cuts.empty() || rng() % 4 == 0) {
    if (!s.cut_batch_ends.empty()) s.cut_batch_ends.back() += (rng() & 1U) != 0 ? 1 : -1;
    return;
  }
  const std::size_t k = rng() % s.cuts.size();
  switch (rng() % 3) {
    case 0: mutate_cut(s.cuts[k], rng); break;
    case 1: s.cuts.push_back(s.cuts[k]); break;
    default: s.cuts.erase(s.cuts.begin() + static_cast<std::ptrdiff_t>(k)); break;
  }
}

void mutate_tool(ToolPose& tool, std::mt19937& rng) {
  switch (rng() % 3) {
    case 0: tool.tip_position_m(rng() % 3) = special_double(rng); break;
    case 1: tool.orientation.coeffs()(rng() % 4) = special_double(rng); break;
    default: tool.mode = static_cast<ToolMode>(special_int(rng)); break;
  }
}

void mutate_snapshot(TissueSnapshot& s, std::mt19937& rng) {
  switch (rng() % 11) {
    case 0: mutate_vector(s.dynamics.displacement_m, rng); break;
    case 1: mutate_vector(s.dynamics.velocity_m_per_s, rng); break;
    case 2: s.dynamics.time_s = special_double(rng); break;
    case 3: mutate_cuts(s, rng); break;
    case 4:
      if (!s.cut_offsets.empty()) s.cut_offsets[rng() % s.cut_offsets.size()].resize(rng() % 4);
      else s.cut_offsets.emplace_back(2);
      break;
    case 5: mutate_vector(s.integrator_state, rng); break;
    case 6: mutate_tool((rng() & 1U) != 0 ? s.tool : s.previous_tool, rng); break;
    case 7: s.applied_tool_position_m(rng() % 3) = special_double(rng); break;
    case 8:
      s.steps_since_park_check = special_int(rng);
      s.steps_since_stiffness = special_int(rng);
      break;
    case 9: s.pending_stiffness = static_cast<TissueSnapshot::PendingStiffness>(rng() % 5); break;
    default: s.model_fingerprint ^= std::uint64_t{1} << (rng() % 64); break;
  }
}

}  // namespace

std::size_t mutate_state(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned int seed) {
  std::mt19937 rng(seed);
  std::optional<Found> found = rng() % 8 == 0 ? std::nullopt : find_snapshot({data, size});
  if (!found) return LLVMFuzzerMutate(data, size, max_size);
  mutate_snapshot(found->snapshot, rng);
  const std::vector<std::uint8_t> snapshot = serialize_snapshot(found->snapshot);
  const std::size_t total = found->length_at + 8 + snapshot.size() + TRAILER_BYTES;
  if (total > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::vector<std::uint8_t> trailer(data + size - TRAILER_BYTES, data + size);
  const std::uint64_t length = snapshot.size();
  std::memcpy(data + found->length_at, &length, sizeof(length));
  std::memcpy(data + found->length_at + 8, snapshot.data(), snapshot.size());
  std::memcpy(data + found->length_at + 8 + snapshot.size(), trailer.data(), TRAILER_BYTES);
  return total;
}

}  // namespace tissue::fuzz
