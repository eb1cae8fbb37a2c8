// The 3x3 contact stiffness K_c the haptic loop renders with (f = f0 + K_c (x - x0)) between
// two tissue updates, in two models (docs/DESIGN.md, "Equations and errata": eq. 4.22):
//
// * effective_static (the reference): the stiffness of the whole constrained body at the
//   contact point, K_c = (P^T K^-1 P)^-1, P (3n x 3) interpolating the contact point from the
//   free unknowns (x_p = P^T u + fixed part). It is the force per unit displacement of the point
//   when the rest of the body settles (static condensation); a quasi-static poke of the full
//   model converges to K_c d as d -> 0 (tests/unit/contact). One factorization, then per point the
//   forward halves of three solves over the rows above the point in the elimination tree alone
//   (CholmodFactor::lower_solve): K_c^-1 = (L^-1 P)^T (L^-1 P).
// * element_local (the cheap option): eq. 4.23 with u_d = [d d d d] is a rigid translation of
//   the tet and gives zero force for every valid K_e (the erratum). The repair used here pushes
//   the contacted face (its three vertices) by d and holds the tet's fourth vertex:
//     f = sum over the face vertices of (R K_e R^T u_d)_i = R K_oo R^T d   (rows of K_e sum to 0),
//   K_oo the diagonal block of the opposite vertex o, i.e.
//     K_local = (A / 3h) R [(lambda + 2 mu) n n^T + mu (I - n n^T)] R^T
//   (A the face's area, h the tet's height over it, n its rest normal). Condensing R K_e R^T to
//   the point with o held instead is singular (the tet rotates freely about o). It knows nothing of
//   the rest of the body. Measured on the frog pinned by its belly (tests/unit/contact): 0.1-0.2
//   times the effective normal stiffness on the back (too soft, as the dissertation found), up to
//   ~240 times it on the slender legs (too stiff), and 1/140 of it next to the pins.
#pragma once

#include "core/fem/corotational.hpp"
#include "core/contact/point_spring.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"
#include "core/named_items.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/system/assembly.hpp"
#include "core/system/dynamics_model.hpp"

#include <Eigen/Core>

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

namespace tissue {

class CholmodFactor;
struct LowerSolutionBuffer;

enum class ContactStiffnessModel { effective_static, element_local };

inline constexpr ItemNames<ContactStiffnessModel, 2> CONTACT_STIFFNESS_MODEL_NAMES{
    "contact stiffness model",
    {{{"effectiveStatic",
       "Stiffness of the whole constrained body at the contact point (static condensation; the reference)"},
      {"elementLocal", "Stiffness of the contacted tetrahedron alone (cheap, approximate)"}}}};

/// Parses "effectiveStatic" / "elementLocal" (CONTACT_STIFFNESS_MODEL_NAMES); throws ParameterError otherwise.
ContactStiffnessModel parse_contact_stiffness_model(std::string_view name);
[[nodiscard]] std::string_view to_string(ContactStiffnessModel model);

/// How the contact point moves with the unknowns: x_p = sum_k weights[k] x(vertex k); rows[k] is
/// the block row of vertex k in the system, -1 for a fixed vertex (it does not move).
struct ContactInterpolation {
  std::array<int, 3> rows{-1, -1, -1};
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();
};

/// The interpolation of the point sum_k weights[k] x(vertices[k]) through the body's unknowns.
ContactInterpolation contact_interpolation(const DofMap& dofs, const std::array<int, 3>& vertices,
                                           const Eigen::Vector3d& weights);

/// Springs along one unit direction d at several points (a pad's: point_contact.hpp, "A pad"):
/// spring j pulls points[j] along d with stiffness_n_per_m[j].
struct DirectedSprings {
  std::vector<ContactInterpolation> points;
  std::vector<double> stiffness_n_per_m;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

/// The matrix K_c is condensed from, for a body with fixed vertices: A = K (the tangent; SPD).
/// `diagonal` is the zero shift it points to (resized here; keep it alive with the result).
ShiftedSystem static_contact_system(const BlockSparseMatrix& tangent, Eigen::VectorXd& diagonal);

// For a body with nothing fixed K is singular (rigid motions): K_c is condensed from the step's
// Newton matrix instead, which the integrator gives (Integrator::newton_stiffness; backward Euler:
// M/h^2 + D/h + K), the stiffness the point meets during one step. It exceeds the static K_c (of
// any supported body) by the inertial part, ~ m_local / h^2.

/// K_c = (P^T A^-1 P)^-1 with CHOLMOD: factorize once per matrix, then any number of points
/// (three solves each). The symbolic analysis is kept while the pattern does not change. The object
/// holds its own copy of A once loaded, so the factorization and the solves may run in another thread
/// while the body goes on (BackgroundContactStiffness); one object is not thread-safe.
class EffectiveContactStiffness {
 public:
  EffectiveContactStiffness();
  ~EffectiveContactStiffness();
  EffectiveContactStiffness(const EffectiveContactStiffness&) = delete;
  EffectiveContactStiffness& operator=(const EffectiveContactStiffness&) = delete;

  /// load() then factorize_loaded().
  void factorize(const ShiftedSystem& system);
  /// Copies A into the object and drops the previous factor. Throws SolverError for a system without
  /// a stiffness or with a diagonal of another size, or when CHOLMOD cannot allocate.
  void load(const ShiftedSystem& system);
  /// Factorizes the loaded A, reading nothing outside the object. Throws SolverError when A is not
  /// positive definite (e.g. K of a body with nothing fixed) or nothing is loaded.
  void factorize_loaded();
  /// K_c [N/m], symmetric positive definite; nothing when the point does not move with the
  /// unknowns (all its weight on fixed vertices: a rigid support). Throws SolverError without a
  /// factor, std::invalid_argument for a row outside the factorized matrix.
  [[nodiscard]] std::optional<Eigen::Matrix3d> stiffness_n_per_m(const ContactInterpolation& point);
  /// K_c of the tissue alone when the factorized matrix also holds the contact spring, k w_i w_j D
  /// at the vertices of `spring_point` (DeformableBody's point spring is in its tangent while set;
  /// D = I, or d d^T for a unit `spring_direction` d, zero meaning none: PointSpring): the spring is
  /// taken out exactly (Sherman-Morrison-Woodbury, from the same forward solves). Without that, the
  /// matrix gives K_c + k D at the spring's own point. Throws std::invalid_argument for k < 0.
  [[nodiscard]] std::optional<Eigen::Matrix3d> stiffness_n_per_m(
      const ContactInterpolation& point, const ContactInterpolation& spring_point, double spring_stiffness_n_per_m,
      const Eigen::Vector3d& spring_direction = Eigen::Vector3d::Zero());
  /// A pad's K_c along its normal d (point_contact.hpp, "A pad"): the force on the tool along d per
  /// unit motion of the tool along d, the body settling, through the springs `tool` (the pad's, the
  /// centre's first): sum k - (K 1)^T U^T (A + U K U^T)^-1 U (K 1), U the springs' points along d and
  /// A the tissue alone, the factorized matrix with the springs `in_matrix` (what it holds of the
  /// pad's, possibly of an earlier pad: DeformableBody's point springs are in its tangent while set)
  /// taken out exactly (Woodbury). The pad's springs are in series with the tissue, so it is finite
  /// wherever the pad presses, on fixed vertices too (the springs alone). Throws as
  /// stiffness_n_per_m, and std::invalid_argument for springs of negative or non-finite stiffness or
  /// lists of different lengths.
  [[nodiscard]] double pad_stiffness_n_per_m(const DirectedSprings& tool, const DirectedSprings& in_matrix);
  using ResponseMatrix = Eigen::Matrix<double, Eigen::Dynamic, 3>;
  /// A^-1 P (rows() x 3): the displacement field of a unit force at `point` along each axis, by three
  /// full solves (stiffness_n_per_m needs only the forward halves). Throws as stiffness_n_per_m.
  [[nodiscard]] const ResponseMatrix& unit_force_response(const ContactInterpolation& point);
  /// x = A^-1 b with the same factor. Throws SolverError without one.
  void solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  /// Rows of the factorized matrix, 0 without a factor.
  [[nodiscard]] int rows() const;

 private:
  /// Whether the point moves with the unknowns; throws as documented above.
  [[nodiscard]] bool check(const ContactInterpolation& point) const;
  /// The Gram matrix (L^-1 Q)^T (L^-1 Q) = Q^T A'^-1 Q of Q = [P of each point] (A' the factorized
  /// matrix) by one sparse forward solve: the rows of the elimination tree the points reach.
  [[nodiscard]] Eigen::MatrixXd gram(std::span<const ContactInterpolation> points);
  /// The same for the columns of DirectedSprings: each point along its springs' direction.
  [[nodiscard]] Eigen::MatrixXd directed_gram(const DirectedSprings& first, const DirectedSprings& second);
  /// Factors the columns in m_columns into a Gram matrix (lower_solve).
  [[nodiscard]] Eigen::MatrixXd gram_of_columns();

  std::unique_ptr<CholmodFactor> m_factor;
  bool m_loaded = false;  ///< the factor holds a matrix the last load() copied (not one before a failed load)
  Eigen::VectorXd m_column;
  Eigen::VectorXd m_solution;
  ResponseMatrix m_response;
  std::vector<std::vector<std::pair<int, double>>> m_columns;  // gram()'s right-hand sides
  std::unique_ptr<LowerSolutionBuffer> m_lower;
};

/// What K_c at a contact point needs besides the factorized matrix, copied from the body when the
/// matrix is loaded (so that the factorization and the solves need nothing of the body).
struct ContactStiffnessRequest {
  ContactInterpolation point;
  std::optional<ContactInterpolation> spring_point;  ///< the contact spring's point, while a spring is set
  double spring_in_matrix_n_per_m = 0.0;             ///< what the matrix holds of the spring
  Eigen::Vector3d spring_direction = Eigen::Vector3d::Zero();  ///< the spring's (PointSpring::direction)
  double rigid_support_n_per_m = 0.0;                ///< K_c = this I at a point on fixed vertices only
  double floor_n_per_m = 0.0;                        ///< K_c's smallest eigenvalue must be above this
  /// A pad's springs (the centre's first) as the tool has them, and as the matrix holds them: K_c is
  /// then the pad's, k d d^T (pad_stiffness_n_per_m; above the floor), and the point's fields are
  /// not used. Empty: a point.
  DirectedSprings pad;
  DirectedSprings pad_in_matrix;
};

/// The request for `point` on `system`: the contact spring, if set, is in the matrix as its tangent
/// share times the system's scale. With `pad` (a pad probe's springs beside the spring, which must
/// be set), the pad's request.
ContactStiffnessRequest contact_stiffness_request(const ShiftedSystem& system, const DofMap& dofs,
                                                  const ContactInterpolation& point,
                                                  const std::optional<PointSpring>& spring,
                                                  double rigid_support_n_per_m, double floor_n_per_m,
                                                  const std::vector<PointSpring>* pad = nullptr);

/// K_c of the tissue alone from the matrix loaded into `effective`: factorizes it, the spring taken out
/// exactly. Nothing when the factor fails, or when K_c is not finite or its smallest eigenvalue is not
/// above the request's floor. Reads nothing but `effective` and `request`. Throws std::invalid_argument
/// for a request that does not fit the matrix (contact_stiffness_request for another body).
std::optional<Eigen::Matrix3d> condense_loaded(EffectiveContactStiffness& effective,
                                               const ContactStiffnessRequest& request);

/// K_c of `request` from the factor `effective` already holds (no factorization: forward solves),
/// the spring taken out as the request says, so its spring fields must be those of the factorized
/// matrix. Nothing as condense_loaded, and without a factor.
std::optional<Eigen::Matrix3d> condense_factored(EffectiveContactStiffness& effective,
                                                 const ContactStiffnessRequest& request);

/// K_c of `request` from `system`, loaded into `effective` and condensed (condense_loaded); nothing
/// when `system` cannot be loaded either.
std::optional<Eigen::Matrix3d> condensed_contact_stiffness(EffectiveContactStiffness& effective,
                                                          const ShiftedSystem& system,
                                                          const ContactStiffnessRequest& request);

/// K_c of the tissue alone at `point` from `system`, factorized into `effective` (the request made
/// by contact_stiffness_request, then condensed as above). A point on fixed vertices only is a rigid support: `rigid_support_n_per_m` I.
/// Nothing when the factor fails, or when K_c is not finite or its smallest eigenvalue is not above
/// `floor_n_per_m`.
std::optional<Eigen::Matrix3d> condensed_contact_stiffness(EffectiveContactStiffness& effective,
                                                          const ShiftedSystem& system, const DofMap& dofs,
                                                          const ContactInterpolation& point,
                                                          const std::optional<PointSpring>& spring,
                                                          double rigid_support_n_per_m, double floor_n_per_m);

/// The elementLocal model (header): R K_oo R^T of tet `tet` with `opposite_local_vertex` (0..3) the
/// vertex not on the contacted face, at the rotation of the last evaluate(). [N/m], SPD.
Eigen::Matrix3d element_local_contact_stiffness(const CorotationalElasticity& elasticity, int tet,
                                                int opposite_local_vertex);
/// The same for a surface triangle (its tet and local face from `surface`).
Eigen::Matrix3d element_local_contact_stiffness(const CorotationalElasticity& elasticity, const SurfaceMesh& surface,
                                                int triangle);

/// n^T K n: force along n per unit displacement along n, the tangential displacement held.
double normal_stiffness_n_per_m(const Eigen::Matrix3d& stiffness, const Eigen::Vector3d& unit_normal);
/// 1 / (n^T K^-1 n): force along n per unit normal displacement, the tangential force zero (a
/// frictionless contact). <= normal_stiffness_n_per_m for SPD K.
double frictionless_normal_stiffness_n_per_m(const Eigen::Matrix3d& stiffness, const Eigen::Vector3d& unit_normal);

/// The stiffness a sliding (frictionless or slipping) contact renders: k n n^T, k the frictionless
/// normal stiffness of the bonded K_c (n^T K n where that is not finite and > 0): moving the tool
/// across n changes nothing, the tissue's tangential stiffness belongs to a contact that sticks.
Eigen::Matrix3d sliding_contact_stiffness_n_per_m(const Eigen::Matrix3d& bonded, const Eigen::Vector3d& unit_normal);

/// The mean edge length of the body's surface triangles at rest [m] (0 for no triangles).
double mean_surface_edge_m(const DeformableBody& body, const SurfaceMesh& surface);

/// The scale of the effective normal contact stiffness of a body: (lambda + 2 mu) times the mean
/// surface edge length at rest (the stiffness of a point load on a mesh of that spacing, up to a
/// factor of order one). Measured on the frog pinned by its belly (tests/unit/contact), n^T K_c n at
/// the triangle centroids is 0.0017 to 14 times this: the low end on the slender legs, the high end
/// on triangles touching the pins, at most 2.2 on the rest (0.7-1.4 on the back).
double contact_stiffness_scale_n_per_m(const DeformableBody& body, const SurfaceMesh& surface);

/// A default for PointContactSettings::spring_stiffness_n_per_m: `factor` times
/// contact_stiffness_scale_n_per_m. The spring's share of the contact's compliance, k_n / (k + k_n),
/// is then at most ~2 / factor away from fixed vertices (14 / factor on triangles touching them,
/// where the contact is nearly rigid anyway). A per-contact k from the K_c at the contact point
/// would be tighter but would change the rendered stiffness from one touch to the next. Throws
/// ParameterError unless factor > 0.
double recommended_contact_spring_stiffness_n_per_m(const DeformableBody& body, const SurfaceMesh& surface,
                                                    double factor = 100.0);

}  // namespace tissue
