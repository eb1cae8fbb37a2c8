// Tissue.quasi_static_poke: the core's quasi-static reference for a probe (core/contact/quasi_static_poke.hpp)
// from Python, as tests/host/test_palpation.cpp takes it: static equilibrium of the uncut body (gravity
// included) with the material point of the rest surface straight below a target pushed there,
// frictionless (the point slides until the reaction is along the normal, as the god-object settles).
// What a haptic loop's settled force on a pressing hand is checked against.
#pragma once

#include "core/tissue.hpp"

#include <pybind11/pybind11.h>

#include <array>

namespace tissue::python {

/// {converged, force_on_tool_n, normal, stiffness_n_per_m (the effective-static K_c there)}.
/// Throws ParameterError for a tissue with cuts (its mesh at rest is not the cut body) or nothing fixed,
/// or a target with no upward-facing surface straight above or below it.
pybind11::dict quasi_static_poke(const Tissue& tissue, const std::array<double, 3>& target_m);

}  // namespace tissue::python
