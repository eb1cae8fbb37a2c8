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
  diagonal = c * c * model.mass_kg() + c * model.mass_damping_kg_per_s();
  return ShiftedSystem{&model.tangent(), 1.0 + c * model.stiffness_damping_s(), &diagonal};
}

}  // namespace tissue
