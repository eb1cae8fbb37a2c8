// The Tissue FMU's description: its variable table (variables.hpp) with the tissue sample, its
// enumeration types, log categories and default experiment.
#include "tissue_fmu/variables.hpp"

#include <algorithm>

namespace tissue::tissue_fmu {
namespace {

using fmi3::EnumerationItem;
using fmi3::EnumerationType;

constexpr auto VARIABLES = tissue_variables(ports::TISSUE_SAMPLE);
static_assert(fmi3::strictly_ordered(VARIABLES), "the variable table must be in increasing value-reference order");

constexpr auto LINEAR_SOLVER_ITEMS = std::to_array<EnumerationItem>({
    {"pcg", 1,
     "Jacobi-preconditioned conjugate gradients (iterative; integrator.pcgTolerance, integrator.pcgMaxIterations)"},
    {"cholmod", 2, "Sparse Cholesky factorization (CHOLMOD, direct, exact)"},
    {"pcgCholesky", 3,
     "CG preconditioned by a lagged CHOLMOD factor, refactorized when the iterations grow or a cut changes the pattern; in the FMU without a worker thread (integrator.pcgTolerance, integrator.pcgMaxIterations)"},
});
constexpr auto INTEGRATOR_ITEMS = std::to_array<EnumerationItem>({
    {"backwardEuler", 1, "Semi-implicit backward Euler, one linear solve per internal step (integrator.linearSolver)"},
    {"ida", 2, "SUNDIALS IDA: variable-order, variable-step BDF with error control (integrator.ida*)"},
});
constexpr auto IDA_LINEAR_SOLVER_ITEMS = std::to_array<EnumerationItem>({
    {"klu", 1, "Sparse LU factorization of the Newton matrix (KLU, direct)"},
    {"krylov", 2, "GMRES, preconditioned by eliminating the velocities and the diagonal of the rest (iterative)"},
});
constexpr auto CONTACT_STIFFNESS_ITEMS = std::to_array<EnumerationItem>({
    {"effectiveStatic", 1,
     "Stiffness of the whole constrained body at the contact point (static condensation; the reference)"},
    {"elementLocal", 2, "Stiffness of the contacted tetrahedron alone (cheap, approximate)"},
});
constexpr auto MATERIAL_MODEL_ITEMS = std::to_array<EnumerationItem>({
    {"corotationalLinear", 1, "Co-rotational linear elasticity (the dissertation's; one linear solve a step)"},
    {"stableNeoHookean", 2,
     "Stable Neo-Hookean hyperelasticity (Smith, de Goes and Kim 2018): inversion-safe, its tangent projected to "
     "positive semi-definite per element"},
});
constexpr auto TOOL_MODE_ITEMS = ports::tool_mode_items();
const auto ENUMERATIONS = std::to_array<EnumerationType>({
    {"LinearSolver", "Linear solver of the backward-Euler step", LINEAR_SOLVER_ITEMS},
    {"MaterialModel", "Elasticity of the tissue", MATERIAL_MODEL_ITEMS},
    {"ContactStiffnessModel", "How the 3x3 contact stiffness K_c is computed", CONTACT_STIFFNESS_ITEMS},
    {"Integrator", "Time integrator of the tissue", INTEGRATOR_ITEMS},
    {"IdaLinearSolver", "Linear solver of IDA's Newton iteration", IDA_LINEAR_SOLVER_ITEMS},
    {"ToolMode", ports::TOOL_MODE_DESCRIPTION, TOOL_MODE_ITEMS},
});

constexpr auto LOG_CATEGORIES = fmi3::layer_log_categories(
    "Calls that returned fmi3Warning, and recoverable problems such as a surface that outgrew its capacity",
    "Cuts made and contacts started/ended");

}  // namespace

fmi3::ModelDescription tissue_model_description(std::span<const fmi3::VariableInfo> variables) {
  return {MODEL_IDENTIFIER,
          INSTANTIATION_TOKEN,
          variables,
          ENUMERATIONS,
          "Real-time XFEM soft-tissue simulation: a co-rotational tetrahedral body cut by a scalpel and touched by a "
          "probe, with the contact force, contact stiffness and deformed surface mesh as outputs",
          LOG_CATEGORIES,
          {0.0, 1.0, 0.01}};
}

const fmi3::ModelDescription& tissue_model_description() {
  static const fmi3::ModelDescription description = tissue_model_description(VARIABLES);
  return description;
}

}  // namespace tissue::tissue_fmu
