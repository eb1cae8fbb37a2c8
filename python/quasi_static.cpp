// Tissue.quasi_static_poke (see quasi_static.hpp).
#include "quasi_static.hpp"

#include "arrays.hpp"
#include "core/contact/quasi_static_poke.hpp"
#include "core/fem/deformable_body.hpp"

#include <pybind11/numpy.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace py = pybind11;

namespace tissue::python {
py::dict quasi_static_poke(const Tissue& tissue, const std::array<double, 3>& target) {
  if (tissue.body().cut_tet_count() > 0) throw ParameterError("quasi_static_poke: the tissue has cuts");
  const Eigen::Vector3d target_m(target[0], target[1], target[2]);
  const TetMesh& mesh = tissue.body().mesh();
  const SurfaceTriangles& triangles = tissue.surface().triangles;
  Eigen::VectorXd rest_m;  // the body is uncut: its unknowns are the mesh vertices'
  tissue.body().positions(Eigen::VectorXd::Zero(tissue.body().dof_count()), rest_m);
  const SurfacePoint start = surface_point_below(target_m, triangles, rest_m);
  if (start.triangle < 0) throw ParameterError("quasi_static_poke: no upward-facing surface above or below the target");
  QuasiStaticPoke poke;
  {
    py::gil_scoped_release release;
    DeformableBody body(mesh, tissue.settings().body);
    QuasiStaticPokeSettings settings;  // as test_palpation.cpp: the contact slides
    settings.force_tolerance = 1e-8;
    settings.friction = PokeFriction::frictionless;
    settings.tangential_tolerance = 1e-3;
    try {
      poke = quasi_static_poke(body, triangles, start, target_m, settings);
    } catch (const std::invalid_argument& error) {  // nothing fixed, a target not finite
      throw ParameterError(std::string("quasi_static_poke: ") + error.what());
    }
  }
  py::dict out;
  out["converged"] = poke.converged;
  out["force_on_tool_n"] = vector3(poke.force_on_tool_n);
  out["normal"] = vector3(poke.normal);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> k = poke.contact_stiffness_n_per_m;
  py::array_t<double> stiffness({3, 3});
  std::copy(k.data(), k.data() + 9, stiffness.mutable_data());
  out["stiffness_n_per_m"] = stiffness;
  return out;
}

}  // namespace tissue::python
