// The Newton matrix shared by every integrator (see integrator.hpp).
#include "core/integrate/integrator.hpp"

#include <cmath>
#include <string>

namespace tissue {

ShiftedSystem newton_stiffness_system(const DynamicsModel& model, double leading_coefficient_per_s,
                                      Eigen::VectorXd& diagonal) {
  const double c = leading_coefficient_per_s;
  if (!(c > 0.0) || !std::isfinite(c)) {
    throw ParameterError("Newton matrix: the leading coefficient must be finite and > 0 1/s, got " +
                         std::to_string(c));
  }
  const RayleighDamping& damping = model.damping();
  diagonal = (c * c + c * damping.mass_damping_per_s) * model.mass_kg();
  return ShiftedSystem{&model.tangent(), 1.0 + c * damping.stiffness_damping_s, &diagonal};
}

}  // namespace tissue
