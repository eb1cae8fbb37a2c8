// fmu_error.hpp - the one exception type of the FMI importer library.
//
// Everything the importer refuses (a broken archive, an invalid model description, a binary
// that lacks FMI functions, a call the FMU's description does not allow) is an FmuError whose
// message names the file, variable or function concerned. A status returned by the FMU is
// never turned into an exception: the thin calls return the fmi3Status.
#pragma once

#include <stdexcept>

namespace tissue::host {

/// Refusal of an FMU, a model description or a call by the importer.
class FmuError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tissue::host
