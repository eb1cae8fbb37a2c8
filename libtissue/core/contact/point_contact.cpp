// The god-object point contact (see point_contact.hpp).
#include "core/contact/point_contact.hpp"

#include "core/material/material.hpp"

#include <algorithm>
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
  if (!(settings.friction_coefficient >= 0.0) || !std::isfinite(settings.friction_coefficient)) {
    throw ParameterError("contact friction coefficient must be finite and >= 0, got " +
                         std::to_string(settings.friction_coefficient));
  }
  if (!(settings.pad_radius_m >= 0.0) || !std::isfinite(settings.pad_radius_m)) {
    throw ParameterError("contact pad radius must be finite and >= 0 m, got " + std::to_string(settings.pad_radius_m));
  }
  if (settings.pad_radius_m > 0.0 && settings.friction_coefficient > 0.0) {
    throw ParameterError("a probe with a pad (contact pad radius " + std::to_string(settings.pad_radius_m) +
                         " m) is frictionless: set the contact friction to 0 or the pad radius to 0");
  }
}

Eigen::Vector3d pad_sample_offset(int k, const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  // Equal areas: the centre's disc holds 1/19 of the area, the rings' annuli 6/19 and 12/19; each
  // ring's samples sit on the radius that halves its annulus's area, the outer ring turned by half
  // a step.
  if (k <= 0) return Eigen::Vector3d::Zero();
  const bool inner = k <= 6;
  const double radius = inner ? std::sqrt(4.0 / PAD_SAMPLES) : std::sqrt(13.0 / PAD_SAMPLES);
  const double angle = inner ? 2.0 * M_PI * (k - 1) / 6.0 : 2.0 * M_PI * (k - 7 + 0.5) / 12.0;
  return radius * (std::cos(angle) * u + std::sin(angle) * v);
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
                          const Eigen::VectorXd& positions_m, const SurfaceBvh& surface, double follow_distance_m,
                          double normal_stiffness_n_per_m) {
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

  // With friction, the last step's force on the tool (the spring as it was, at the positions it left).
  const Eigen::Vector3d last_force_n = m_in_contact && m_settings.friction_coefficient > 0.0
                                           ? force_on_tool_n(surface, positions_m)
                                           : Eigen::Vector3d::Zero();
  const Eigen::Vector3d last_hip_m = m_hip_m;
  m_hip_m = hip_m;
  m_pad.clear();  // sampled anew below while the contact goes on
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
    m_pad_pressed = 0;
    return false;
  }
  m_in_contact = true;
  // The smooth normal, not the face's: pulled along the face normal, a point probe's pit (a cone of
  // faces around the vertex it presses) throws the proxy from face to face, 1.4 mm at a time, the
  // force swinging by +-1.7 N on 1.8 N (a 5 mm box swept at 15 mm/s).
  m_normal = smooth_normal(projection.point, surface.triangles(), m_adjacency, positions_m);
  if (m_settings.pad_radius_m > 0.0 && !m_pad_axis.isZero(0.0)) {
    // A pad's face is across the tool's axis, whatever the surface under it does: the smooth normal
    // at the centre of a pit tilts with any asymmetry of the pit, the disc would tilt with it and
    // press the low side deeper (a 4 mm grid pressed 2 mm by an 8 mm pad: 20 degrees).
    m_normal = m_pad_axis.dot(m_normal) >= 0.0 ? m_pad_axis : Eigen::Vector3d(-m_pad_axis);
  }
  if (m_settings.friction_coefficient > 0.0 && was_in_contact) {
    // The normal force's change the HIP's motion along -m asks for: the contact's normal stiffness
    // in series with the spring.
    const double k = m_settings.spring_stiffness_n_per_m;
    const double series_n_per_m = normal_stiffness_n_per_m > 0.0 && std::isfinite(normal_stiffness_n_per_m)
                                      ? normal_stiffness_n_per_m * k / (normal_stiffness_n_per_m + k)
                                      : 0.0;
    stick_or_slip(projection, last_force_n, series_n_per_m * (hip_previous_m - hip_m).dot(m_normal), positions_m,
                  surface);
  } else {
    m_proxy = projection.point;
    m_proxy_position_m = projection.position_m;
    m_sticking = m_settings.friction_coefficient > 0.0;  // a new contact with friction sticks
    m_friction_on_body_n.setZero();
  }
  m_depth_m = (m_proxy_position_m - hip_m).norm();
  // The probe touches the mesh's surface only: a cut face's corners are not vertices the spring can
  // act on (they move with the enriched unknowns), so a probe reaching into a crack feels nothing.
  if (m_proxy.triangle >= m_touchable_triangles) {
    release();
    return false;
  }
  sample_pad(positions_m, surface, follows_m, (hip_m - last_hip_m).dot(m_normal));
  return true;
}

double PointContact::centre_stiffness_n_per_m() const {
  const double k = m_settings.spring_stiffness_n_per_m;
  return m_settings.pad_radius_m > 0.0 ? k / PAD_SAMPLES : k;
}

void PointContact::sample_pad(const Eigen::VectorXd& positions_m, const SurfaceBvh& surface, double follows_m,
                              double drawn_back_m) {
  m_pad.clear();
  if (!(m_settings.pad_radius_m > 0.0)) return;
  // The disc's axes: the one of the coordinate axes least along n, made orthogonal to it.
  const Eigen::Vector3d& n = m_normal;
  Eigen::Index least = 0;
  n.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d u = (Eigen::Vector3d::Unit(least) - n[least] * n).normalized();
  const Eigen::Vector3d v = n.cross(u);
  // Each sample presses the surface point in front of it along the axis (the nearest crossing of the
  // line through it, on a face turned to the disc), not the closest one: under a pressed disc the
  // closest point to a sample near the rim jumps onto the pit's wall as the disc slides.
  const double reach_m = 2.0 * m_settings.pad_radius_m;
  const std::uint32_t pressed_before = m_pad_pressed;
  m_pad_pressed = 0;
  for (int k = 1; k < PAD_SAMPLES; ++k) {
    const Eigen::Vector3d target_m = m_hip_m + m_settings.pad_radius_m * pad_sample_offset(k, u, v);
    surface.intersect_segment(target_m - reach_m * n, target_m + reach_m * n, positions_m, m_segment_hits);
    const SurfaceBvh::SegmentHit* front = nullptr;
    double front_distance_m = 0.0;
    for (const SurfaceBvh::SegmentHit& hit : m_segment_hits) {
      if (hit.triangle >= m_touchable_triangles) continue;  // a cut face
      if (triangle_area_normal(surface.triangle(hit.triangle), positions_m).dot(n) <= 0.0) continue;
      const double distance_m = std::abs(2.0 * hit.segment_parameter - 1.0) * reach_m;
      if (front == nullptr || distance_m < front_distance_m) {
        front = &hit;
        front_distance_m = distance_m;
      }
    }
    // Pressed: the surface point lies beyond the disc's plane; or the sample was pressed at the last
    // update, the point still beyond where the plane was (its spring pushed, it did not pull) and
    // short of the plane now by less than the pressed surface's rebound (the contact's rule, above).
    // Without the second, a disc drawn back by 20 um left every sample short of its plane, the force
    // fell to the centre's share, and the hand holding the pad on the organ rang at 50 Hz between 1
    // and 9 N; without its middle condition, samples the tissue had sunk away from stayed held.
    if (front == nullptr) continue;
    const double beyond_m = (2.0 * front->segment_parameter - 1.0) * reach_m;
    const bool was_pressed = ((pressed_before >> k) & 1U) != 0;
    const bool follows = was_pressed && beyond_m + drawn_back_m > 0.0 && beyond_m > -follows_m;
    if (!(beyond_m > 0.0 || follows)) continue;
    m_pad_pressed |= 1U << k;
    m_pad.push_back(PointSpring{surface.triangle(front->triangle), front->barycentric, target_m,
                                centre_stiffness_n_per_m(), m_settings.spring_tangent_fraction, n,
                                Eigen::Vector3d::Zero()});
  }
}

void PointContact::stick_or_slip(const SurfaceProjection& closest, const Eigen::Vector3d& last_force_on_tool_n,
                                 double normal_force_change_n, const Eigen::VectorXd& positions_m,
                                 const SurfaceBvh& surface) {
  const Eigen::Vector3d& m = m_normal;
  const double mu = m_settings.friction_coefficient;
  const double cone_n = mu * std::max(last_force_on_tool_n.dot(m), 0.0);  // the last step's
  const Eigen::Vector3d tangential_force_n = last_force_on_tool_n - last_force_on_tool_n.dot(m) * m;
  bool slip = false;
  Eigen::Vector3d drag = Eigen::Vector3d::Zero();  // t: the way the tool drags the surface
  const Eigen::Vector3d held_m = surface_point_position_m(m_proxy, surface.triangles(), positions_m);
  if (m_sticking) {
    slip = tangential_force_n.norm() > cone_n;
    if (slip) drag = -tangential_force_n.normalized();
  } else {
    const Eigen::Vector3d previous = m_friction_on_body_n - m_friction_on_body_n.dot(m) * m;
    drag = previous.normalized();
    slip = !drag.isZero(0.0) && (m_hip_m - held_m).dot(drag) > cone_n / m_settings.spring_stiffness_n_per_m;
  }
  const bool was_sticking = m_sticking;
  m_sticking = !slip;
  const double predicted_normal_n = std::max(last_force_on_tool_n.dot(m) + normal_force_change_n, 0.0);
  m_friction_on_body_n = slip ? Eigen::Vector3d(mu * predicted_normal_n * drag) : Eigen::Vector3d::Zero();
  if (m_sticking && was_sticking) {  // the material point stays held
    m_proxy_position_m = held_m;
    return;
  }
  m_proxy = closest.point;  // slipping, or held from the point under the tool
  m_proxy_position_m = closest.position_m;
}

std::optional<PointSpring> PointContact::spring(const SurfaceBvh& surface) const {
  if (!m_in_contact) return std::nullopt;
  return PointSpring{surface.triangle(m_proxy.triangle),   m_proxy.barycentric,
                     m_hip_m,
                     centre_stiffness_n_per_m(),
                     m_settings.spring_tangent_fraction,
                     m_sticking ? Eigen::Vector3d::Zero() : m_normal,
                     m_friction_on_body_n};
}

void PointContact::apply(const SurfaceBvh& surface, PointSpringTerm& term, const TermLayout& layout) const {
  term.set(spring(surface), layout, m_in_contact ? m_pad : std::vector<PointSpring>());
}

Eigen::Vector3d PointContact::force_on_tool_n(const SurfaceBvh& surface, const Eigen::VectorXd& positions_m) const {
  if (!m_in_contact) return Eigen::Vector3d::Zero();
  Eigen::Vector3d force_on_body_n =
      spring_force_on_body_n(*spring(surface), surface_point_position_m(m_proxy, surface.triangles(), positions_m));
  return -(force_on_body_n + springs_force_on_body_n(m_pad, positions_m));
}

}  // namespace tissue
