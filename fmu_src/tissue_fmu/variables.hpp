// The Tissue FMU's variables: value references and the table of modelDescription/Tissue.xml (name,
// type, causality, variability, unit, start, range, dimensions, description) in the FMI layer's
// terms (fmi3/variable_table.hpp). The XML is the contract; tests/fmu/test_model_description.cpp
// keeps this table equal to it. Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"

#include <cstdint>
#include <string_view>

namespace tissue::tissue_fmu {

inline constexpr std::string_view INSTANTIATION_TOKEN = "{6d0f5e2a-93b1-4c8e-a7d4-2f1b9c3e5a71}";
inline constexpr std::string_view MODEL_IDENTIFIER = "Tissue";
enum class Vr : std::uint32_t {
  time = 0,
  // parameters
  mesh = 1,
  young_modulus = 2,
  poisson_ratio = 3,
  density = 4,
  damping_alpha = 5,
  damping_beta = 6,
  gravity = 7,
  fixed_axis = 8,
  fixed_fraction = 9,
  linear_solver = 10,
  pcg_tolerance = 11,
  pcg_max_iterations = 12,
  warm_start = 13,
  step_size = 14,
  contact_enabled = 15,
  cutting_enabled = 16,
  mesh_output_enabled = 17,
  probe_radius = 18,
  blade_length = 19,
  contact_spring_stiffness = 20,
  contact_stiffness_model = 21,
  contact_stiffness_refresh_steps = 22,
  min_volume_fraction = 23,
  // structural parameters
  vertex_capacity = 24,
  triangle_capacity = 25,
  // inputs
  tool_position = 30,
  tool_orientation = 31,
  tool_mode = 32,
  // outputs
  contact_active = 40,
  contact_point = 41,
  contact_normal = 42,
  contact_force = 43,
  contact_stiffness = 44,
  contact_depth = 45,
  vertex_count = 50,
  triangle_count = 51,
  surface_revision = 52,
  vertex_positions = 53,
  triangles = 54,
  cut_triangle_count = 55,
  cut_tets = 60,
  enriched_vertices = 61,
  dofs = 62,
  kinetic_energy = 63,
  elastic_energy = 64,
  blade_depth = 65,
  integrator_iterations = 66,
  // parameters added with issue 10 (the integrator choice, the hand's speed limit)
  integrator_method = 70,
  ida_relative_tolerance = 71,
  ida_absolute_tolerance = 72,
  ida_max_order = 73,
  ida_max_step = 74,
  ida_linear_solver = 75,
  tool_max_speed = 76
};

/// The Tissue FMU's description: identity, variables, enumeration types.
const fmi3::ModelDescription& tissue_model_description();

}  // namespace tissue::tissue_fmu
