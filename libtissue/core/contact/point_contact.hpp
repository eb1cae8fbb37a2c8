// Point contact of the probe (dissertation 4.4.1; docs/DESIGN.md, "Contact"): a god-object proxy
// (Zilles and Salisbury 1995) held on the deforming surface as a material point (triangle,
// barycentric), and the implicit spring that applies the contact to the tissue.
//
// Why a spring to the HIP and not f = K_c d: the spring ties the proxy's material point x_p to
// the haptic interaction point with stiffness k, and it enters the implicit step (force and
// tangent), so the body answers with its full co-rotational response. At equilibrium
//   f_int(u) - f_ext = k (HIP - x_p(u)) P,
// i.e. the surface point sits on the HIP up to |f| / k, and the force is the quasi-static
// reaction of the whole model to pushing the surface to the HIP (less |f| / k of depth: a
// relative error k_n / (k + k_n) for a contact of normal stiffness k_n, hence k >> k_n). Because
// the proxy is re-projected every step to the surface point closest to the HIP, the spring has no
// tangential part at rest: the contact settles frictionless. f = K_c d with d measured to a proxy
// that does not move the body would instead render a rigid wall of stiffness K_c that the tissue
// never feels.
//
// The spring is not Rayleigh-damped (issue 9). It stands for the rigid tool, not for tissue, but
// in the tangent whole it would be damped as tissue is, beta k v_p against a fixed frame: the tool
// dragged a viscous beta k v (beta = 0.01 s, k ~ 1e5 N/m, a 5.75 cm/s press: 60 N where the tissue
// gives 2 N). It enters the tangent with the share undamped_tangent_fraction(h, beta)
// (spring_tangent_fraction), so the backward-Euler step takes it undamped; the tissue keeps its
// own damping, and pressing at a speed v the tool feels the quasi-static force plus beta K_n v
// (K_n the contact's normal stiffness; tests/physics/test_contact_press.cpp). The force on the
// tool is the spring's at the end of the step, k (x_p - HIP), the reaction of the body.
//
// Sliding (issue 42): the spring pulls along the surface's smooth normal n at the proxy alone
// (k n n^T; PointSpring::direction), so the material point slides freely across n within the step
// and the contact is frictionless. An isotropic spring held the material point tangentially within
// the step too; the re-projection then released only the tangential stretch |f_t| / k per step,
// and the body's tangential load relaxed by a factor (1 - k_t / k) per step (k_t the tangential
// contact stiffness): with k = 100 k_t, a drag of 19-35 % of the normal force on a probe swept at
// 5-30 mm/s over a flat box, stick-slip on the organ. The normal is the interpolated vertex normal
// (smooth_normal), not the face's: along the face normal a point probe's pit (a cone of faces
// around the vertex it presses) threw the proxy from face to face (docs/DESIGN.md, "Palpating the
// organ").
//
// With Coulomb friction (coefficient mu > 0; the friction cone, as CHAI3D's finger proxy) the
// contact sticks or slips:
// * sticking: the proxy stays the material point it was (no re-projection) and the spring pulls
//   along every axis: the tissue is dragged with the tool;
// * slipping: the proxy is the closest point and the spring pulls along m alone, as without
//   friction, and a constant force mu f_n t acts on the body there (PointSpring::
//   constant_force_on_body_n): f_n the normal force predicted for the step (the last one plus the
//   contact's normal stiffness times the HIP's motion along -m), t the direction the tool drags the
//   surface. Explicit: its tangent would be unsymmetric (with the last f_n as it was, a sweep over
//   a 5 mm box at 30 mm/s dragged 0.28-0.36 f_n for mu = 0.3). (An isotropic spring with the proxy
//   on the cone's rim was tried: the body's tangential load then followed a falling normal force
//   only at the rate k_t / k per step, 0.3 mu f_n too much within a few mm.)
// A sticking contact slips when the last step's force (the body's answer included) left the cone,
// |f_t| > mu f_n, along t = -f_t / |f_t|; a slipping one sticks, held from the point under the
// tool, when the tool is no longer ahead of the surface point it was over along t by more than the
// cone's reach mu f_n / k (it stopped or turned). A new contact starts sticking.
//
// A pad (PointContactSettings::pad_radius_m > 0): the probe ends in a flat disc of that radius
// through the HIP, across the normal at the proxy (a fingertip, a blunt palpation probe). Under a
// point the force follows the mesh, not the tissue: a point load has no finite stiffness in a
// continuum, and on a mesh the stiffness under a point is ~ E h (h the local edge length; the
// 6.1k-tet organ felt twice as stiff as the 52k-tet one, docs/BENCHMARKS.md, "The physics
// resolution chosen for the slot"), while under a disc of radius a it tends to the continuum's
// ~ 2 a E / (1 - nu^2) (Boussinesq's flat punch) once h < a. The disc is sampled at PAD_SAMPLES
// points of equal area (the centre, rings of 6 and 12); each sample is the surface point closest to
// it, and where the disc has pressed into the surface (the point outside the disc's plane, on a face
// that faces the disc) a spring of stiffness k / PAD_SAMPLES pulls it along the normal to the disc:
// a layer of uniform stiffness per area between the rigid tool and the tissue, k in all when the
// whole disc presses. The proxy is the centre sample (its spring is the point contact's, with that
// share of k). Like the point, the pad slides (the samples are found anew at every update); it is
// frictionless (a pad with friction is refused).
#pragma once

#include "core/collide/surface_bvh.hpp"
#include "core/contact/point_spring.hpp"
#include "core/contact/surface_point.hpp"
#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace tissue {

struct PointContactSettings {
  /// Stiffness k of the spring from the proxy's material point to the HIP [N/m], finite and > 0.
  /// Choose it >> the contact's normal stiffness: recommended_contact_spring_stiffness_n_per_m().
  double spring_stiffness_n_per_m = 1.0e4;
  /// The spring's PointSpring::tangent_fraction, in (0, 1]: undamped_tangent_fraction(h, beta) for
  /// the backward-Euler step of h the spring acts in (the spring is not tissue: see above); 1
  /// damps it like tissue, beta k, which the tool then feels as a drag of beta k v.
  double spring_tangent_fraction = 1.0;
  /// > 0: a HIP found inside the surface without crossing it (the surface moved over a tool that
  /// stood still or moved less) starts a contact too, if it is at most this deep; 0: crossings only.
  double passed_over_depth_m = 0.0;
  /// Coulomb friction coefficient mu of the tool on the surface, finite and >= 0 (0: frictionless).
  double friction_coefficient = 0.0;
  /// The probe's pad radius (the header), finite and >= 0 [m]; 0: a point.
  double pad_radius_m = 0.0;
};

/// The samples of a pad: the centre, then rings of 6 and 12 (equal areas of the disc).
inline constexpr int PAD_SAMPLES = 19;
static_assert(PAD_SAMPLES <= 32, "the samples pressed are kept as bits of a 32-bit mask");
/// Sample k's offset from the pad's centre in the disc's plane, in units of its radius (the first is
/// the centre), along the unit axes `u`, `v` of that plane.
Eigen::Vector3d pad_sample_offset(int k, const Eigen::Vector3d& u, const Eigen::Vector3d& v);

/// Throws ParameterError unless the spring stiffness is finite and > 0, its tangent fraction in (0, 1],
/// the friction coefficient finite and >= 0 and the pad radius finite and >= 0, and for a pad with
/// friction.
void validate(const PointContactSettings& settings);

class PointContact {
 public:
  /// Throws ParameterError for invalid settings.
  explicit PointContact(PointContactSettings settings = {});

  /// One god-object update for the tool tip (HIP) moving from `hip_previous_m` to `hip_m`,
  /// against the surface of `surface` (its triangles, refitted to `positions_m`, 3 per vertex).
  /// * Not in contact: contact starts where the segment first enters the surface (crossing a
  ///   triangle against its outward normal; exits, e.g. of a tool that began inside, are skipped)
  ///   if the HIP is then inside (the pseudo-normal at the proxy: a tool pushed through a thin part is
  ///   held at the side it entered). A surface that moved over the HIP (no crossing, the HIP inside
  ///   by a ray's parity) starts a contact only with settings().passed_over_depth_m > 0 and the HIP
  ///   at most that deep: a tool switched on deep inside the body does not snap to its surface.
  /// * In contact (or just started): the proxy slides over the current surface to the locally
  ///   closest point to the HIP (slide_to_closest_point; frictionless); contact ends when the HIP
  ///   is on the outer side of the surface there (pseudo-normal test) by `follow_distance_m` or more.
  ///   A pressed surface follows a tool drawn back by less than its quasi-static rebound, f_n / k_n
  ///   (the caller's estimate from the last step's force and contact stiffness; 0: it follows
  ///   nothing): the surface here is the last step's, still pressed, and would rise to the tool within
  ///   the step. Ending the contact instead lets the released surface spring up through the tool
  ///   unresisted for a whole step, and the next step finds the tool deep inside (issue 20: a hand
  ///   easing off a 1 N press by 10 um, under 1 mm/s, got 13 N back and chattered).
  /// * With friction, the contact sticks or slips (the header); a slip's friction force is mu times
  ///   the normal force predicted at the new HIP from the last one and `normal_stiffness_n_per_m`
  ///   (the contact's, in series with the spring; 0: the last one as it was).
  /// Returns in_contact(). Throws std::invalid_argument (state unchanged) for a non-finite HIP or
  /// positions that do not cover the surface's vertices.
  bool update(const Eigen::Vector3d& hip_previous_m, const Eigen::Vector3d& hip_m, const Eigen::VectorXd& positions_m,
              const SurfaceBvh& surface, double follow_distance_m = 0.0, double normal_stiffness_n_per_m = 0.0);
  /// Ends a contact (e.g. the tool mode changed).
  void release() {
    m_in_contact = false;
    m_pad.clear();
    m_pad_pressed = 0;
  }
  /// The tool's axis for the next update (unit, or zero: none): a pad's face is across it, and the
  /// contact's normal is the axis turned out of the surface (the header).
  void set_pad_axis(const Eigen::Vector3d& axis) {
    m_pad_axis = axis.allFinite() && axis.norm() > 0.0 ? Eigen::Vector3d(axis.normalized()) : Eigen::Vector3d::Zero();
  }
  /// The probe touches the surface's triangles below `triangle_count` only (the mesh's own; those after
  /// them are a cut's faces): update() ends a contact whose proxy is on another, and a pad's samples
  /// leave them out. All by default.
  void set_touchable_triangles(int triangle_count) { m_touchable_triangles = triangle_count; }

  [[nodiscard]] bool in_contact() const { return m_in_contact; }
  /// The proxy as a material point (meaningful while in contact).
  [[nodiscard]] const SurfacePoint& proxy() const { return m_proxy; }
  /// The proxy's position at the last update [m].
  [[nodiscard]] const Eigen::Vector3d& proxy_position_m() const { return m_proxy_position_m; }
  /// Unit outward smooth normal of the surface at the proxy at the last update (smooth_normal), or
  /// for a pad its face's normal (the tool's axis): the direction the springs pull along.
  [[nodiscard]] const Eigen::Vector3d& normal() const { return m_normal; }
  /// The HIP of the last update [m].
  [[nodiscard]] const Eigen::Vector3d& hip_m() const { return m_hip_m; }
  /// |HIP - proxy| at the last update while in contact, else 0 [m].
  [[nodiscard]] double penetration_depth_m() const { return m_in_contact ? m_depth_m : 0.0; }
  /// With friction: the contact sticks (the proxy held as a material point). False without friction,
  /// slipping, or out of contact.
  [[nodiscard]] bool sticking() const { return m_in_contact && m_sticking; }
  [[nodiscard]] const PointContactSettings& settings() const { return m_settings; }

  /// The spring from the proxy's material point to the HIP, for the body's PointSpringTerm;
  /// nothing when not in contact.
  [[nodiscard]] std::optional<PointSpring> spring(const SurfaceBvh& surface) const;
  /// A pad's springs besides it, those of the samples pressed at the last update (empty for a point,
  /// or out of contact).
  [[nodiscard]] const std::vector<PointSpring>& pad_springs() const { return m_pad; }

  /// What the contact carries from step to step (the work buffers and the adjacency are rebuilt).
  struct State {
    bool in_contact = false;
    SurfacePoint proxy;
    Eigen::Vector3d proxy_position_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d hip_m = Eigen::Vector3d::Zero();
    double depth_m = 0.0;
    bool sticking = false;
    Eigen::Vector3d friction_on_body_n = Eigen::Vector3d::Zero();  ///< slipping: mu f_n t
    std::uint32_t pad_pressed = 0;  ///< a pad's samples pressed at the last update (bit k: sample k)
  };
  [[nodiscard]] State state() const {
    return State{m_in_contact, m_proxy,    m_proxy_position_m,   m_normal,       m_hip_m,
                 m_depth_m,    m_sticking, m_friction_on_body_n, m_pad_pressed};
  }
  void restore(const State& state) {
    m_in_contact = state.in_contact;
    m_proxy = state.proxy;
    m_proxy_position_m = state.proxy_position_m;
    m_normal = state.normal;
    m_hip_m = state.hip_m;
    m_depth_m = state.depth_m;
    m_sticking = state.sticking;
    m_friction_on_body_n = state.friction_on_body_n;
    m_pad_pressed = state.pad_pressed;
    m_pad.clear();  // the pad's springs are the body's term's (saved with it); the next update samples anew
  }
  /// term.set(spring(surface), layout, pad_springs()): `term` attached to the body whose
  /// term_layout() is `layout`.
  void apply(const SurfaceBvh& surface, PointSpringTerm& term, const TermLayout& layout) const;
  /// The force on the tool, k D (x_p - HIP) - F (PointSpring; D = n n^T unless sticking), the proxy's
  /// material point at `positions_m` (e.g. after the step), i.e. minus the spring's force on the body,
  /// a pad's springs' included; zero when not in contact. [N]
  [[nodiscard]] Eigen::Vector3d force_on_tool_n(const SurfaceBvh& surface, const Eigen::VectorXd& positions_m) const;

 private:
  /// Whether `point_m` is inside the surface by a ray's parity (the ray's hits stay in m_segment_hits).
  bool inside_by_parity(const Eigen::Vector3d& point_m, const Eigen::VectorXd& positions_m, const SurfaceBvh& surface);
  /// A pad's springs for the contact as updated (the header); `follows_m`: how far short of the
  /// disc's plane a sample pressed at the last update still presses (the pressed surface's rebound,
  /// as update() follows a tool); `drawn_back_m`: how far the plane moved out along the normal since.
  void sample_pad(const Eigen::VectorXd& positions_m, const SurfaceBvh& surface, double follows_m,
                  double drawn_back_m);
  /// The stiffness of the proxy's spring: k, or its share for a pad [N/m].
  [[nodiscard]] double centre_stiffness_n_per_m() const;
  /// With friction, a contact that goes on sticks or slips (the header); sets the proxy.
  void stick_or_slip(const SurfaceProjection& closest, const Eigen::Vector3d& last_force_on_tool_n,
                     double normal_force_change_n, const Eigen::VectorXd& positions_m, const SurfaceBvh& surface);
  PointContactSettings m_settings;
  bool m_in_contact = false;
  SurfacePoint m_proxy;
  Eigen::Vector3d m_proxy_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_normal = Eigen::Vector3d::Zero();
  Eigen::Vector3d m_hip_m = Eigen::Vector3d::Zero();
  double m_depth_m = 0.0;
  bool m_sticking = false;
  Eigen::Vector3d m_friction_on_body_n = Eigen::Vector3d::Zero();
  std::vector<PointSpring> m_pad;                      // a pad's springs (sample_pad)
  std::uint32_t m_pad_pressed = 0;                     // bit k: sample k pressed at the last update
  int m_touchable_triangles = std::numeric_limits<int>::max();
  Eigen::Vector3d m_pad_axis = Eigen::Vector3d::Zero();
  VertexTriangles m_adjacency;                         // rebuilt when the surface grows (a cut)
  std::vector<SurfaceBvh::SegmentHit> m_segment_hits;  // work buffer
};

}  // namespace tissue
