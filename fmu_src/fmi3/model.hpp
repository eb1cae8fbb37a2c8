// What an FMU model implements for the FMI 3.0 layer (instance.hpp): the physics behind one
// instance, reading its parameters and inputs from the layer's ValueStore and computing its
// outputs. The layer owns the state machine, argument checks, typed get/set of stored values and
// logging; a model sees only calls the state table allowed. Errors are exceptions: VariableError or
// any std::exception for a refused value (fmi3Error), CallOrderError for a call the model cannot
// take now (fmi3Error); the layer turns them into statuses.
#pragma once

#include "fmi3/value_store.hpp"
#include "fmi3/variable_table.hpp"
#include "serial/byte_stream.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

namespace tissue::fmi3 {

/// The log channels a model may write to (the layer filters by the importer's categories).
enum class LogLevel { event, warning };
using ModelLogger = std::function<void(LogLevel level, const std::string& message)>;

/// What a model is given when the importer instantiates the FMU.
struct ModelContext {
  std::string instance_name;
  std::string resource_path;  ///< the unpacked FMU's resources directory ("" if not given)
  ModelLogger log;
};

/// A saved model state (FMI get FMU state); the layer keeps it next to the stored values.
class ModelState {
 public:
  virtual ~ModelState() = default;
};

/// Outcome of one doStep: done, or stopped early at `last_successful_time_s` (fmi3Discard).
struct StepOutcome {
  bool completed = true;
  double last_successful_time_s = 0.0;
  bool warning = false;  ///< completed, with something the log explains (fmi3Warning)
};

/// How many internal steps of `internal_step_s` a doStep over `step_s` from `current_time_s` takes,
/// for a model at `model_time_s`: the one rule of every FMU of the project. Throws VariableError
/// unless the communication point is the model's time and the step a whole multiple of the internal
/// step (both to 1e-9, relative).
long whole_internal_steps(double model_time_s, double current_time_s, double step_s, double internal_step_s);

class Model {
 public:
  virtual ~Model() = default;

  /// Refuses (throws, with a message naming the variable) parameters the model cannot run with:
  /// called on an fmi3Set* that sets a parameter, with the values as they would be after it (and on
  /// instantiation and a deserialized state). Delegates to the core's own validate(). A set of
  /// inputs alone is not: the layer checks what the schema says of them (type, size, finiteness,
  /// enumeration items, min_norm), the model checks them once per step where it uses them.
  virtual void validate_parameters(const ValueStore& values) const = 0;
  /// Parameters were set (values committed); the model rebuilds from them when it next needs to.
  virtual void parameters_changed() {}

  virtual void enter_initialization_mode(double start_time_s) = 0;
  /// Builds the model from the parameters if it is not built yet.
  virtual void exit_initialization_mode() = 0;
  /// Advances by `step_s` from `current_time_s` (checked to be the model's time by the model).
  virtual StepOutcome do_step(double current_time_s, double step_s) = 0;
  /// Back to the state after instantiation (the layer has reset the values to their starts).
  virtual void reset() = 0;

  // Outputs and the independent variable; `values.size()` is the variable's element count (with
  // arrays sized by the structural parameters). The defaults refuse.
  virtual void get_float64(const VariableInfo& info, std::span<double> values);
  virtual void get_uint32(const VariableInfo& info, std::span<std::uint32_t> values);
  virtual void get_uint64(const VariableInfo& info, std::span<std::uint64_t> values);
  virtual void get_int64(const VariableInfo& info, std::span<std::int64_t> values);
  virtual void get_boolean(const VariableInfo& info, std::span<bool> values);
  /// A Binary output's bytes, owned by the model and valid until the model's next call (each Binary
  /// variable its own buffer: one fmi3GetBinary may ask for several).
  virtual std::span<const std::uint8_t> get_binary(const VariableInfo& info);

  /// The model's state (not the stored values, which the layer saves); throws if there is none.
  [[nodiscard]] virtual std::unique_ptr<ModelState> save() const = 0;
  /// Restores a state this model (or one with the same parameters) saved; the stored values are
  /// already those saved with it. Throws (nothing changed) if it cannot.
  virtual void restore(const ModelState& state) = 0;
  virtual void serialize(const ModelState& state, serial::ByteWriter& writer) const = 0;
  /// Throws serial::FormatError or another exception for bytes that are not a state of this model.
  [[nodiscard]] virtual std::unique_ptr<ModelState> deserialize(serial::ByteReader& reader) const = 0;
};

/// Each FMU defines these two (one per shared library): the description the layer drives and the
/// factory of its model. `values` outlives the model.
const ModelDescription& model_description();
std::unique_ptr<Model> make_model(const ModelContext& context, const ValueStore& values);

}  // namespace tissue::fmi3
