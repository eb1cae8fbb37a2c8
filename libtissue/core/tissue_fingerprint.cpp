// The model fingerprint (see model_fingerprint in tissue.hpp): what a saved state must match.
#include "core/tissue.hpp"
#include "core/tissue_settings_schema.hpp"

#include <array>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace tissue {
namespace {

// FNV-1a (64 bit) over the bytes of trivially copyable values: the model fingerprint.
class Fingerprint {
 public:
  template <class T>
  void add(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    for (size_t k = 0; k < sizeof(T); ++k) m_hash = (m_hash ^ bytes[k]) * 0x100000001b3ULL;
  }
  // A setting's value: its kind, then its bytes (a text's length, then its characters).
  void add(const SettingValue& value) {
    add(value.index());
    std::visit(
        [this](const auto& v) {
          if constexpr (std::is_same_v<std::decay_t<decltype(v)>, std::string>) {
            add(v.size());
            for (const char c : v) add(c);
          } else {
            add(v);
          }
        },
        value);
  }
  template <class T>
  void add_all(const std::vector<T>& values) {
    add(values.size());
    for (const T& value : values) add(value);
  }
  [[nodiscard]] std::uint64_t value() const { return m_hash; }

 private:
  std::uint64_t m_hash = 0xcbf29ce484222325ULL;
};

}  // namespace

std::uint64_t model_fingerprint(const TetMesh& mesh, const TissueSettings& settings) {
  Fingerprint f;
  for (const Eigen::Vector3d& x : mesh.rest_positions_m) f.add(std::array<double, 3>{x.x(), x.y(), x.z()});
  f.add_all(mesh.tets);
  const BodySettings& body = settings.body;
  // Every setting the schema holds, in its order; then what only the core sets.
  for_each_tissue_setting(settings, [&](const SettingInfo&, const SettingValue& value) { f.add(value); });
  if (!mesh.regions.empty()) {  // a mesh of one region adds nothing here
    f.add_all(mesh.tet_regions);
    for (const Material& material : resolve_region_materials(mesh.regions, body.material, body.region_materials)) {
      f.add(material.young_modulus_pa);
      f.add(material.poisson_ratio);
      f.add(material.density_kg_per_m3);
      if (material.mass_damping_per_s) f.add(*material.mass_damping_per_s);  // older fingerprints stay
    }
  }
  f.add_all(body.fixed_vertices);
  f.add(body.reserve.extra_row_fraction);  // field by field: a struct's padding bytes are not values
  f.add(body.reserve.row_capacity_factor);
  if (body.reserve.spare_row_capacity != 0) f.add(body.reserve.spare_row_capacity);  // older fingerprints stay
  f.add(body.rotation.max_iterations);
  f.add(body.rotation.max_error_rad);
  const IdaSettings& ida = settings.integrator.ida;
  f.add(ida.max_internal_steps);
  f.add(settings.integrator.newton.trigger_angle_rad);
  f.add(settings.integrator.newton.max_iterations);
  f.add(settings.integrator.newton.energy_guard_angle_rad);
  f.add(settings.integrator.newton.line_search);
  if (settings.solver.pcg.matrix_precision != MatrixPrecision::automatic) f.add(settings.solver.pcg.matrix_precision);
  if (settings.solver.kind == LinearSolverKind::pcg_cholesky) {  // so that older fingerprints stay as they were
    f.add(settings.solver.refresh.refresh_iterations);           // background_refactor changes no result
    f.add(settings.solver.refresh.pickup_setups);
    f.add(settings.solver.refresh.follow_rotations);
    f.add(settings.solver.refresh.refactor_on_growth);
  }
  return f.value();
}

}  // namespace tissue
