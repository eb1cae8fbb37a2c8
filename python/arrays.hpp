// The Python module's conversions between Eigen vectors and what Python passes and gets (numpy
// arrays that own a copy, so nothing dangles after a step or a tick), shared by its files.
#pragma once

#include <pybind11/numpy.h>

#include <Eigen/Core>

#include <algorithm>
#include <array>

namespace tissue::python {

/// A float64 array [3] holding a copy of v.
inline pybind11::array_t<double> vector3(const Eigen::Vector3d& v) {
  pybind11::array_t<double> out(3);
  std::copy(v.data(), v.data() + 3, out.mutable_data());
  return out;
}

inline Eigen::Vector3d to_vector3(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }

}  // namespace tissue::python
