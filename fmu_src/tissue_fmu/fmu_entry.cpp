// The Tissue FMU's entry points for the FMI layer (fmi3/model.hpp): compiled into Tissue.so only,
// next to the layer's C ABI.
#include "fmi3/model.hpp"
#include "tissue_fmu/tissue_model.hpp"
#include "tissue_fmu/variables.hpp"

namespace tissue::fmi3 {

const ModelDescription& model_description() { return tissue_fmu::tissue_model_description(); }

std::unique_ptr<Model> make_model(const ModelContext& context, const ValueStore& values) {
  return std::make_unique<tissue_fmu::TissueModel>(context, values);
}

}  // namespace tissue::fmi3
