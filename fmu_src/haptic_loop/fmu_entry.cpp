// The HapticLoop FMU's entry points for the FMI layer (fmi3/model.hpp): compiled into
// HapticLoop.so only, next to the layer's C ABI.
#include "fmi3/model.hpp"
#include "haptic_loop/haptic_model.hpp"
#include "haptic_loop/variables.hpp"

namespace tissue::fmi3 {

const ModelDescription& model_description() { return haptic_fmu::haptic_loop_model_description(); }

std::unique_ptr<Model> make_model(const ModelContext& context, const ValueStore& values) {
  return std::make_unique<haptic_fmu::HapticModel>(context, values);
}

}  // namespace tissue::fmi3
