#include "support/accepted_mesh.hpp"

#include "core/parameter_error.hpp"
#include "core/tissue.hpp"
#include "support/promise.hpp"

#include <cmath>

namespace tissue::fuzz {

void require_steps(const TetMesh& mesh) {
  TissueSettings settings;  // the product's defaults
  try {
    Tissue tissue(mesh, settings);
    for (int step = 0; step < 10; ++step) tissue.step();
    if (!tissue.current_positions_m().allFinite()) broken("an accepted mesh stepped to a non-finite state");
  } catch (const ParameterError& error) {
    require_message(error.what(), "tissue");
  }
}

}  // namespace tissue::fuzz
