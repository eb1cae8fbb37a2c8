// Backward Euler's energy guard (see backward_euler.hpp): a step whose end holds more energy than
// its start gives back the gain from its motion, part by part.
#include "core/integrate/backward_euler.hpp"
#include "core/system/rows_left.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tissue {
namespace {

// The model's part of each block row (DynamicsModel::row_parts): 0 for every row of a model of one
// part (or whose list does not match its rows), -1 for a row no element uses.
class RowParts {
 public:
  RowParts(const DynamicsModel& model, Eigen::Index rows) : m_parts(model.row_parts()) {
    if (m_parts != nullptr && static_cast<Eigen::Index>(m_parts->size()) != rows) m_parts = nullptr;
  }
  int operator()(Eigen::Index row) const { return m_parts == nullptr ? 0 : (*m_parts)[static_cast<size_t>(row)]; }

 private:
  const std::vector<int>* m_parts;
};

// Adds a row of mass `m` and velocity `v` to its part's momentum and mass (the lists grown to hold it).
void add_to_part(std::vector<Eigen::Vector3d>& momentum, std::vector<Eigen::Vector3d>& mass, int part,
                 const Eigen::Vector3d& m, const Eigen::Vector3d& v) {
  const auto at = static_cast<size_t>(part);
  if (at >= mass.size()) {
    momentum.resize(at + 1, Eigen::Vector3d::Zero());
    mass.resize(at + 1, Eigen::Vector3d::Zero());
  }
  momentum[at] += m.cwiseProduct(v);
  mass[at] += m;
}

}  // namespace

// Energy projection (Dinev et al. 2018): E = 1/2 v^T M v + potential. If the step's end holds more
// than its start, v1 = mean + s (v1 - mean) on every row, mean the mass-weighted mean velocity of the
// row's part (DynamicsModel::row_parts: no force acts between parts, so each keeps its momentum; a
// row no element uses keeps its velocity), with s in [0, 1) chosen to bring E back; if the mean
// motions alone are too much, they are scaled too (with one mean for the whole body, a piece cut
// free and falling beside a part that turned lost speed at every guarded step). If the end's
// potential alone is above the start's energy, no velocity brings it back (the gain is in the
// positions): the rows of the elements the step turned past the guard's angle lose their motion
// relative to their part's turning rows' mean, and the others keep theirs (zeroing every velocity
// stopped every part, a falling one too, and kept the hatched frog's pre-stressed chips from
// settling: docs/DESIGN.md). `state` has u1 and still v0.
bool BackwardEuler::guard_energy(DynamicsModel& model, const DynamicState& state, double h) {
  const Eigen::VectorXd& mass = model.mass_kg();
  const Eigen::Index blocks = mass.size() / 3;
  // The rows that left the dynamics (parked parts) are left out: their free fall is exact, and
  // taking the step's excess from them drained the parts falling away (they hold most of the motion
  // relative to the mean): the hatched frog's pieces stopped in mid-air while later strokes cut.
  const std::vector<std::uint8_t>* left = model.rows_left();
  const auto in = [left](Eigen::Index r) { return !row_left(left, r); };
  const Eigen::VectorXd& load = model.external_force_n();
  double kinetic_before_j = 0.0, kinetic_after_j = 0.0;
  double left_potential_before_j = 0.0, left_potential_after_j = 0.0;  // -f . u of the rows left
  for (Eigen::Index r = 0; r < blocks; ++r) {
    const auto m = mass.segment<3>(3 * r);
    if (!in(r)) {
      const auto u1 = state.displacement_m.segment<3>(3 * r);
      left_potential_after_j -= load.segment<3>(3 * r).dot(u1);
      left_potential_before_j -= load.segment<3>(3 * r).dot(u1 - h * m_end_velocity.segment<3>(3 * r));
      continue;
    }
    const auto v0 = state.velocity_m_per_s.segment<3>(3 * r);
    const auto v1 = m_end_velocity.segment<3>(3 * r);
    kinetic_before_j += 0.5 * v0.dot(m.cwiseProduct(v0));
    kinetic_after_j += 0.5 * v1.dot(m.cwiseProduct(v1));
  }
  double potential_before_j = m_start_potential_j;  // a pass over the elements saved
  if (!std::isfinite(potential_before_j)) {
    m_end_displacement.noalias() = state.displacement_m - h * m_end_velocity;  // u0
    potential_before_j = model.potential_energy_j(m_end_displacement);
  }
  const double before_j = kinetic_before_j + potential_before_j - left_potential_before_j;
  // The end's potential: the corrections' last line search found it at the same u1, when it did.
  // Else by the next step's start evaluated now, ahead (a whole assembly that the next step takes
  // instead of its own: 3.3 ms of the organ's 19 saved), where the model will; else by a pass of its own.
  double potential_after_j = m_end_potential_j;
  if (!std::isfinite(potential_after_j) && evaluates_ahead() &&
      model.evaluate_ahead(state.displacement_m, m_internal_force_n)) {
    m_end_evaluated = true;
    potential_after_j = model.potential_energy_at_last_evaluate_j();
  }
  if (!std::isfinite(potential_after_j)) {
    potential_after_j = model.potential_energy_j(state.displacement_m);
    m_end_potential_by_pass = m_settings.newton.linearize_at_predicted_end;
  }
  if (!std::isfinite(before_j) || !std::isfinite(potential_after_j)) return false;  // the model cannot say
  potential_after_j -= left_potential_after_j;
  if (kinetic_after_j + potential_after_j <= before_j) return false;
  if (potential_after_j >= before_j) return brake_turning_rows(model, h);
  // The parts only now (found again after a cut: a union-find over the elements).
  const RowParts part_of(model, blocks);
  const double mean_kinetic_j = part_means(model);
  const double relative_kinetic_j = std::max(0.0, kinetic_after_j - mean_kinetic_j);
  const double room_j = before_j - potential_after_j;
  const bool relative_only = room_j >= mean_kinetic_j && relative_kinetic_j > 0.0;
  const double s = relative_only ? std::sqrt((room_j - mean_kinetic_j) / relative_kinetic_j)
                                 : (kinetic_after_j > 0.0 ? std::sqrt(room_j / kinetic_after_j) : 0.0);
  for (Eigen::Index r = 0; r < blocks; ++r) {
    if (!in(r)) continue;
    auto v1 = m_end_velocity.segment<3>(3 * r);
    const int part = part_of(r);
    if (!relative_only) {
      v1 *= s;
    } else if (part >= 0) {
      const Eigen::Vector3d& mean_velocity = m_part_momentum[static_cast<size_t>(part)];
      v1 = mean_velocity + s * (v1 - mean_velocity);
    }
  }
  return true;
}

double BackwardEuler::part_means(const DynamicsModel& model) {
  const Eigen::VectorXd& mass = model.mass_kg();
  const RowParts part_of(model, mass.size() / 3);
  const std::vector<std::uint8_t>* left = model.rows_left();
  m_part_momentum.clear();
  m_part_mass.clear();
  double mean_kinetic_j = 0.0;  // first the rows no element uses (each its own mean)
  for (Eigen::Index r = 0; r < mass.size() / 3; ++r) {
    if (row_left(left, r)) continue;
    const auto m = mass.segment<3>(3 * r);
    const auto v1 = m_end_velocity.segment<3>(3 * r);
    const int part = part_of(r);
    if (part < 0) {
      mean_kinetic_j += 0.5 * v1.dot(m.cwiseProduct(v1));
    } else {
      add_to_part(m_part_momentum, m_part_mass, part, m, v1);
    }
  }
  for (size_t part = 0; part < m_part_mass.size(); ++part) {
    Eigen::Vector3d& mean_velocity = m_part_momentum[part];  // the momentum becomes the mean velocity
    mean_velocity = mean_velocity.cwiseQuotient(m_part_mass[part].cwiseMax(1e-300));
    mean_kinetic_j += 0.5 * m_part_mass[part].dot(mean_velocity.cwiseProduct(mean_velocity));
  }
  return mean_kinetic_j;
}

bool BackwardEuler::brake_turning_rows(const DynamicsModel& model, double h) {
  m_end_displacement.noalias() = h * m_end_velocity;  // the step's increment
  model.mark_turning_rows(m_end_displacement, m_settings.newton.energy_guard_angle_rad, m_turning_rows);
  const Eigen::VectorXd& mass = model.mass_kg();
  const std::vector<std::uint8_t>* left = model.rows_left();
  const Eigen::Index blocks = mass.size() / 3;
  const RowParts part_of(model, blocks);
  // (A row no element uses turns with none: each braked row has a part.)
  const auto braked = [&](Eigen::Index r) {
    return m_turning_rows[static_cast<size_t>(r)] != 0 && !row_left(left, r) && part_of(r) >= 0;
  };
  m_part_momentum.clear();
  m_part_mass.clear();
  for (Eigen::Index r = 0; r < blocks; ++r) {
    if (!braked(r)) continue;
    add_to_part(m_part_momentum, m_part_mass, part_of(r), mass.segment<3>(3 * r), m_end_velocity.segment<3>(3 * r));
  }
  bool any = false;
  for (Eigen::Index r = 0; r < blocks; ++r) {
    if (!braked(r)) continue;
    const auto part = static_cast<size_t>(part_of(r));
    if (!(m_part_mass[part].minCoeff() > 0.0)) continue;
    m_end_velocity.segment<3>(3 * r) = m_part_momentum[part].cwiseQuotient(m_part_mass[part]);
    any = true;
  }
  return any;
}

}  // namespace tissue
