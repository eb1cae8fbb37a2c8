// ReferenceTrace, ErrorAccumulator and pareto_front (see compare_metrics.hpp).
#include "compare/compare_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace tissue::host {
namespace {

constexpr std::string_view TRACE_MAGIC = "tissue-compare-trace-1";

void put_u64(std::string& out, std::uint64_t value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(value));
}

void put_doubles(std::string& out, const std::vector<double>& values) {
  put_u64(out, values.size());
  out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
}

class ByteReader {
 public:
  explicit ByteReader(std::string_view bytes) : m_bytes(bytes) {}
  std::uint64_t u64() {
    std::uint64_t value = 0;
    take(&value, sizeof(value));
    return value;
  }
  std::vector<double> doubles() {
    const std::uint64_t count = u64();
    if (count > (m_bytes.size() - m_at) / sizeof(double)) throw std::runtime_error("reference trace: truncated");
    std::vector<double> values(count);
    take(values.data(), count * sizeof(double));
    return values;
  }
  void take(void* into, std::size_t size) {
    if (size > m_bytes.size() - m_at) throw std::runtime_error("reference trace: truncated");
    std::memcpy(into, m_bytes.data() + m_at, size);
    m_at += size;
  }
  [[nodiscard]] bool done() const { return m_at == m_bytes.size(); }

 private:
  std::string_view m_bytes;
  std::size_t m_at = 0;
};

double distance3(const double* a, const double* b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

void ReferenceTrace::add(double t_s, std::span<const double> positions, const std::array<double, 3>& force,
                         double energy) {
  time_s.push_back(t_s);
  positions_m.insert(positions_m.end(), positions.begin(),
                     positions.begin() + static_cast<std::ptrdiff_t>(3 * vertex_count));
  force_n.insert(force_n.end(), force.begin(), force.end());
  energy_j.push_back(energy);
}

std::string ReferenceTrace::to_bytes() const {
  std::string out(TRACE_MAGIC);
  put_u64(out, vertex_count);
  put_doubles(out, time_s);
  put_doubles(out, positions_m);
  put_doubles(out, force_n);
  put_doubles(out, energy_j);
  return out;
}

ReferenceTrace ReferenceTrace::from_bytes(std::string_view bytes) {
  if (bytes.substr(0, TRACE_MAGIC.size()) != TRACE_MAGIC) throw std::runtime_error("reference trace: not a trace");
  ByteReader in(bytes.substr(TRACE_MAGIC.size()));
  ReferenceTrace trace;
  trace.vertex_count = static_cast<std::size_t>(in.u64());
  trace.time_s = in.doubles();
  trace.positions_m = in.doubles();
  trace.force_n = in.doubles();
  trace.energy_j = in.doubles();
  const std::size_t k = trace.time_s.size();
  if (!in.done() || trace.positions_m.size() != 3 * trace.vertex_count * k || trace.force_n.size() != 3 * k ||
      trace.energy_j.size() != k) {
    throw std::runtime_error("reference trace: inconsistent sizes");
  }
  return trace;
}

ErrorAccumulator::ErrorAccumulator(const ReferenceTrace& reference) : m_reference(reference) {}

void ErrorAccumulator::add(double t_s, std::span<const double> positions, const std::array<double, 3>& force,
                           double energy) {
  if (!m_mismatch.empty()) return;
  const std::size_t k = m_points;
  const std::size_t n = m_reference.vertex_count;
  if (k >= m_reference.points()) {
    m_mismatch = "more communication points than the reference";
    return;
  }
  const double t_ref = m_reference.time_s[k];
  if (std::abs(t_s - t_ref) > 1e-9 * std::max(1.0, std::abs(t_ref))) {
    m_mismatch = "point " + std::to_string(k) + " is at t = " + std::to_string(t_s) + " s, the reference's at " +
                 std::to_string(t_ref) + " s (a discarded step)";
    return;
  }
  if (positions.size() < 3 * n) {
    m_mismatch = "fewer surface vertices than the reference";
    return;
  }
  const double* reference = m_reference.positions_m.data() + 3 * n * k;
  for (std::size_t v = 0; v < n; ++v) {
    const double d = distance3(positions.data() + 3 * v, reference + 3 * v);
    m_sum_squared_m2 += d * d;
    m_max_m = std::max(m_max_m, d);
  }
  const double df = distance3(force.data(), m_reference.force_n.data() + 3 * k);
  m_force_sum_squared_n2 += df * df;
  m_energy_max_j = std::max(m_energy_max_j, std::abs(energy - m_reference.energy_j[k]));
  m_points = k + 1;
}

ErrorMetrics ErrorAccumulator::result() const {
  ErrorMetrics metrics;
  if (!m_mismatch.empty()) {
    metrics.why_not = m_mismatch;
    return metrics;
  }
  if (m_points != m_reference.points()) {
    metrics.why_not = "stopped after " + std::to_string(m_points) + " of " + std::to_string(m_reference.points()) +
                      " communication points";
    return metrics;
  }
  if (m_points == 0 || m_reference.vertex_count == 0) {
    metrics.why_not = "nothing to compare";
    return metrics;
  }
  metrics.valid = true;
  const double values = static_cast<double>(m_points) * static_cast<double>(m_reference.vertex_count);
  metrics.rms_error_m = std::sqrt(m_sum_squared_m2 / values);
  metrics.max_error_m = m_max_m;
  metrics.force_error_n = std::sqrt(m_force_sum_squared_n2 / static_cast<double>(m_points));
  metrics.energy_drift_j = m_energy_max_j;
  return metrics;
}

std::vector<bool> pareto_front(std::span<const double> cost, std::span<const double> error,
                               const std::vector<bool>& eligible) {
  const std::size_t n = cost.size();
  std::vector<bool> front(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    if (!eligible[i]) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < n && !dominated; ++j) {
      if (j == i || !eligible[j]) continue;
      dominated = cost[j] <= cost[i] && error[j] <= error[i] && (cost[j] < cost[i] || error[j] < error[i]);
    }
    front[i] = !dominated;
  }
  return front;
}

}  // namespace tissue::host
