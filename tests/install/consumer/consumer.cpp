// The consumer of the installed package (tests/install/check_install.sh builds it against the prefix):
// the frog from the installed meshes, held at its tail and sagging under gravity, cut across by a
// scalpel drawn at 0.2 m/s; then the installed Tissue FMU stepped through the FMI importer. Prints
// what it saw and exits non-zero when the frog did not sag, was not cut, or the FMU did not step.
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/tissue.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <exception>
#include <algorithm>
#include <filesystem>
#include <optional>
#include <vector>

namespace {

const std::filesystem::path DATA_DIR = TISSUE_DATA_DIR;

// The lowest point of the frog's free (head) end: it sags below its rest height under gravity.
double lowest_free_y_m(const tissue::Tissue& frog, const tissue::TetMesh& mesh) {
  Eigen::VectorXd x;
  frog.vertex_positions(x);
  double lowest = 1e9;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<std::size_t>(v)].x() > 0.04) lowest = std::min(lowest, x(3 * v + 1));
  }
  return lowest;
}

int cut_the_frog() {
  const tissue::TetMesh mesh = tissue::read_mesh(DATA_DIR / "meshes/frog.veg");
  tissue::TissueSettings settings;
  settings.step_size_s = 0.01;
  settings.body.fixed_vertices = tissue::vertices_at_minimum(mesh, 0, 0.3);  // the tail end held
  settings.interaction.blade_length_m = 0.1;
  tissue::Tissue frog(mesh, settings);
  const double rest_lowest_y_m = lowest_free_y_m(frog, mesh);

  // A vertical blade (the tool axis +z, up from its tip 3 cm below the frog) across the body at x = 0.
  tissue::ToolPose scalpel;
  scalpel.mode = tissue::ToolMode::scalpel;
  for (int step = 0; step < 80; ++step) {
    const double y_m = -0.07 + 0.002 * step;  // 0.2 m/s
    scalpel.tip_position_m = {0.0, y_m, -0.03};
    frog.set_tool(scalpel);
    frog.step();
  }
  const int cut_tets = frog.body().cut_tet_count();
  const double sag_m = rest_lowest_y_m - lowest_free_y_m(frog, mesh);
  std::printf("core: %d tets, cut %d, the free end sagged %.1f mm in %.2f s\n", mesh.tet_count(), cut_tets,
              1e3 * sag_m, frog.time_s());
  return cut_tets > 0 && sag_m > 1e-3 ? 0 : 1;
}

int step_the_fmu() {
  const tissue::host::Fmu3 fmu(DATA_DIR / "fmus/Tissue.fmu");
  tissue::host::Fmu3Instance tissue_fmu(fmu, "consumer");
  tissue_fmu.enter_initialization_mode(std::nullopt, 0.0, std::nullopt);
  tissue_fmu.exit_initialization_mode();
  int ok_steps = 0;
  for (int step = 0; step < 10; ++step) {
    if (tissue_fmu.do_step(0.01 * step, 0.01).status == fmi3OK) ++ok_steps;
  }
  std::vector<double> time_s;
  tissue_fmu.get_float64("sample.time", time_s);
  std::printf("fmu: %s, %d of 10 steps OK, sample.time %.3f s\n", fmu.description().model_name().c_str(), ok_steps,
              time_s.empty() ? -1.0 : time_s[0]);
  tissue_fmu.terminate();
  return ok_steps == 10 && !time_s.empty() && std::abs(time_s[0] - 0.1) < 1e-9 ? 0 : 1;
}

}  // namespace

int main() {
  try {
    const int core = cut_the_frog();
    const int fmu = step_the_fmu();
    return core | fmu;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 1;
  }
}
