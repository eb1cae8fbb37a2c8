// How far a run is from the reference, and which runs are worth their cost. The reference run is
// recorded at every communication point (ReferenceTrace); every other run is compared with it
// point by point as it goes (ErrorAccumulator), so no run but the reference is kept in memory.
// Errors are measured on the mesh's original surface vertices: the first N rows of
// surface.vertexPositions, N = surface.vertexCount at the start (cuts append cut-face corners
// after them, which need not match between runs).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::host {

/// The reference run at each communication point k (rows in step order).
struct ReferenceTrace {
  std::size_t vertex_count = 0;     ///< N, the mesh's original surface vertices
  std::vector<double> time_s;       ///< K points
  std::vector<double> positions_m;  ///< K x N x 3
  std::vector<double> force_n;      ///< K x 3, contact.force
  std::vector<double> energy_j;     ///< K, kineticEnergy + elasticEnergy

  [[nodiscard]] std::size_t points() const { return time_s.size(); }
  /// Appends point k.
  void add(double t_s, std::span<const double> positions, const std::array<double, 3>& force, double energy);
  /// Exact binary form (native doubles), for sending the trace to other processes.
  [[nodiscard]] std::string to_bytes() const;
  /// Throws std::runtime_error for bytes that are not a trace.
  [[nodiscard]] static ReferenceTrace from_bytes(std::string_view bytes);
};

/// A run against the reference; `valid` false (and `why_not` said) when it cannot be compared.
struct ErrorMetrics {
  bool valid = false;
  std::string why_not;
  double rms_error_m = 0.0;     ///< RMS over points and vertices of |x - x_ref|
  double max_error_m = 0.0;     ///< largest |x - x_ref|
  double force_error_n = 0.0;   ///< RMS over points of |F - F_ref|
  double energy_drift_j = 0.0;  ///< largest |E - E_ref|, E = kinetic + elastic
};

/// Compares a run with the reference point by point, in the order the run reaches them.
class ErrorAccumulator {
 public:
  explicit ErrorAccumulator(const ReferenceTrace& reference);
  /// The run's next communication point; `positions` holds at least the reference's N rows.
  void add(double t_s, std::span<const double> positions, const std::array<double, 3>& force, double energy);
  /// Valid when every reference point was matched at the same time with N vertices.
  [[nodiscard]] ErrorMetrics result() const;

 private:
  const ReferenceTrace& m_reference;
  std::size_t m_points = 0;
  std::string m_mismatch;
  double m_sum_squared_m2 = 0.0, m_max_m = 0.0, m_force_sum_squared_n2 = 0.0, m_energy_max_j = 0.0;
};

/// Which points are on the Pareto front of (cost, error), both minimized: none other among the
/// eligible is at most as costly and at most as wrong, and better in one. Ineligible: false.
[[nodiscard]] std::vector<bool> pareto_front(std::span<const double> cost, std::span<const double> error,
                                             const std::vector<bool>& eligible);

}  // namespace tissue::host
