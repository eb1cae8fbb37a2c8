// The god-object point contact (see point_contact.hpp).
#include "core/contact/point_contact.hpp"

#include "core/material/material.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// Length of the ray that decides whether a HIP is inside the surface (far beyond any specimen).
constexpr double PASSED_OVER_RAY_M = 100.0;

}  // namespace

void validate(const PointContactSettings& settings) {
  if (!(settings.spring_stiffness_n_per_m > 0.0) || !std::isfinite(settings.spring_stiffness_n_per_m)) {
    throw ParameterError("contact spring stiffness must be finite and > 0 N/m, got " +
                         std::to_string(settings.spring_stiffness_n_per_m));
  }
  if (!(settings.passed_over_depth_m >= 0.0) || !std::isfinite(settings.passed_over_depth_m)) {
    throw ParameterError("contact passed-over depth must be finite and >= 0 m, got " +
                         std::to_string(settings.passed_over_depth_m));
  }
  if (!(settings.spring_tangent_fraction > 0.0 && settings.spring_tangent_fraction <= 1.0)) {
    throw ParameterError("contact spring tangent fraction must be in (0, 1], got " +
                         std::to_string(settings.spring_tangent_fraction));
  }
}

bool PointContact::inside_by_parity(const Eigen::Vector3d& point_m, const Eigen::VectorXd& positions_m,
                                    const SurfaceBvh& surface) {
  // Inside when a ray from the point crosses the surface an odd number of times (a direction off
  // the axes, so that a ray along a grid's faces or edges is unlikely). Leaves the hits of the ray
  // in m_segment_hits.
  const Eigen::Vector3d direction = Eigen::Vector3d(0.5279, 0.6173, 0.5832).normalized();
  surface.intersect_segment(point_m, point_m + PASSED_OVER_RAY_M * direction, positions_m, m_segment_hits);
  return m_segment_hits.size() % 2 == 1;
}

PointContact::PointContact(PointContactSettings settings) : m_settings(settings) { validate(m_settings); }

bool PointContact::update(const Eigen::Vector3d& hip_previous_m, const Eigen::Vector3d& hip_m,
                          const Eigen::VectorXd& positions_m, const SurfaceBvh& surface, double follow_distance_m) {
  if (!hip_m.allFinite() || !hip_previous_m.allFinite()) {
    throw std::invalid_argument("point contact: the tool tip position is not finite");
  }
  if (positions_m.size() % 3 != 0) {
    throw std::invalid_argument("point contact: positions must hold 3 values per vertex, got " +
                                std::to_string(positions_m.size()));
  }
  const int vertex_count = static_cast<int>(positions_m.size() / 3);
  if (m_adjacency.triangle_count != surface.triangle_count() ||
      static_cast<int>(m_adjacency.begin.size()) != vertex_count + 1) {
    m_adjacency.build(surface.triangles(), vertex_count);  // throws (state unchanged) for ids out of range
  }

  m_hip_m = hip_m;
  SurfacePoint start = m_proxy;
  const bool was_in_contact = m_in_contact;
  if (!m_in_contact) {
    surface.intersect_segment(hip_previous_m, hip_m, positions_m, m_segment_hits);
    const Eigen::Vector3d motion = hip_m - hip_previous_m;
    int entered = -1;
    for (size_t k = 0; k < m_segment_hits.size() && entered < 0; ++k) {
      const SurfaceBvh::SegmentHit& hit = m_segment_hits[k];
      if (motion.dot(triangle_area_normal(surface.triangle(hit.triangle), positions_m)) < 0.0) {
        entered = static_cast<int>(k);
      }
    }
    if (entered >= 0) {
      const SurfaceBvh::SegmentHit& entry = m_segment_hits[static_cast<size_t>(entered)];
      // The god-object holds a tool pushed through a thin part at the side it entered (no parity
      // test here: that is the point of a proxy; tool.maxSpeed bounds how far a step can push).
      start = SurfacePoint{entry.triangle, entry.barycentric};
    } else {
      if (!(m_settings.passed_over_depth_m > 0.0)) return false;
      if (!inside_by_parity(hip_m, positions_m, surface)) return false;
      const SurfaceBvh::SegmentHit* nearest = &m_segment_hits.front();
      for (const SurfaceBvh::SegmentHit& hit : m_segment_hits) {
        if (hit.segment_parameter < nearest->segment_parameter) nearest = &hit;
      }
      start = SurfacePoint{nearest->triangle, nearest->barycentric};
      const SurfaceProjection inside =
          slide_to_closest_point(hip_m, start, surface.triangles(), m_adjacency, positions_m);
      if (inside.distance_m > m_settings.passed_over_depth_m) return false;
      start = inside.point;
    }
  }

  const SurfaceProjection projection =
      slide_to_closest_point(hip_m, start, surface.triangles(), m_adjacency, positions_m);
  const double outside_m = (hip_m - projection.position_m).dot(projection.normal);
  const double follows_m = was_in_contact && std::isfinite(follow_distance_m) ? follow_distance_m : 0.0;
  if (outside_m >= follows_m) {  // the HIP is outside, farther than the surface follows: separation
    m_in_contact = false;
    return false;
  }
  m_in_contact = true;
  m_proxy = projection.point;
  m_proxy_position_m = projection.position_m;
  // The spring pulls along the smooth normal alone, not the face's: pulled along the face normal,
  // a point probe's pit (a cone of faces around the vertex it presses) throws the proxy from face to
  // face, 1.4 mm at a time, the force swinging by +-1.7 N on 1.8 N (a 5 mm box swept at 15 mm/s).
  m_normal = smooth_normal(projection.point, surface.triangles(), m_adjacency, positions_m);
  m_depth_m = projection.distance_m;
  return true;
}

std::optional<PointSpring> PointContact::spring(const SurfaceBvh& surface) const {
  if (!m_in_contact) return std::nullopt;
  return PointSpring{surface.triangle(m_proxy.triangle),   m_proxy.barycentric,
                     m_hip_m,
                     m_settings.spring_stiffness_n_per_m,
                     m_settings.spring_tangent_fraction,
                     m_normal};
}

void PointContact::apply(const SurfaceBvh& surface, PointSpringTerm& term, const TermLayout& layout) const {
  term.set(spring(surface), layout);
}

Eigen::Vector3d PointContact::force_on_tool_n(const SurfaceBvh& surface, const Eigen::VectorXd& positions_m) const {
  if (!m_in_contact) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d proxy_m = surface_point_position_m(m_proxy, surface.triangles(), positions_m);
  return m_settings.spring_stiffness_n_per_m * m_normal * m_normal.dot(proxy_m - m_hip_m);
}

}  // namespace tissue
