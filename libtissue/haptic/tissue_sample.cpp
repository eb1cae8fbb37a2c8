#include "haptic/tissue_sample.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue::haptic {

namespace {

constexpr double NORMAL_LENGTH_TOLERANCE = 1e-6;
/// K_c or D_c differing from its PSD projection by less than this (relative, Frobenius) is rounding.
constexpr double STIFFNESS_ROUNDING = 1e-12;

/// `matrix` replaced by its nearest symmetric PSD matrix; whether that changed it beyond rounding.
bool project_to_symmetric_psd(Eigen::Matrix3d& matrix) {
  const Eigen::Matrix3d symmetric = 0.5 * (matrix + matrix.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(symmetric);
  Eigen::Vector3d eigenvalues = eigen.eigenvalues();
  Eigen::Matrix3d projected = symmetric;
  if (eigenvalues.minCoeff() < 0.0) {
    eigenvalues = eigenvalues.cwiseMax(0.0);
    projected = eigen.eigenvectors() * eigenvalues.asDiagonal() * eigen.eigenvectors().transpose();
  }
  const bool repaired = (projected - matrix).norm() > STIFFNESS_ROUNDING * matrix.norm();
  matrix = projected;
  return repaired;
}

void require_finite(bool finite, const char* field) {
  if (!finite) throw std::invalid_argument(std::string("TissueSample: ") + field + " is not finite");
}

}  // namespace

SampleRepair prepare_sample(TissueSample& sample) {
  require_finite(std::isfinite(sample.time_s), "time_s");
  require_finite(sample.contact_point_m.allFinite(), "contact_point_m");
  require_finite(sample.contact_normal.allFinite(), "contact_normal");
  require_finite(sample.force_on_tool_n.allFinite(), "force_on_tool_n");
  require_finite(sample.contact_stiffness_n_per_m.allFinite(), "contact_stiffness_n_per_m");
  require_finite(sample.contact_damping_n_s_per_m.allFinite(), "contact_damping_n_s_per_m");
  require_finite(sample.tool_position_m.allFinite(), "tool_position_m");
  require_finite(std::isfinite(sample.blade_depth_m), "blade_depth_m");
  if (sample.blade_depth_m < 0.0) throw std::invalid_argument("TissueSample: blade_depth_m is negative");
  const double normal_length = sample.contact_normal.norm();
  const bool plane = sample.contact_active || sample.surface_near;
  if (plane && !(std::abs(normal_length - 1.0) <= NORMAL_LENGTH_TOLERANCE)) {
    throw std::invalid_argument("TissueSample: contact_normal is not a unit vector (length " +
                                std::to_string(normal_length) + ")");
  }

  // Everything checked: from here on the sample is only repaired.
  if (plane) sample.contact_normal /= normal_length;
  SampleRepair repair;
  repair.stiffness_repaired = project_to_symmetric_psd(sample.contact_stiffness_n_per_m);
  repair.damping_repaired = project_to_symmetric_psd(sample.contact_damping_n_s_per_m);
  return repair;
}

}  // namespace tissue::haptic
