// Loading the embedded frog, or a mesh file by path.
#include "resources/default_mesh.hpp"

#include <string>

namespace tissue {

TetMesh load_default_mesh(MeshWarnings* warnings) {
  return parse_veg(resources::frog_veg_text(), "embedded:frog.veg", warnings);
}

TetMesh load_mesh(std::string_view name_or_path, MeshWarnings* warnings) {
  if (name_or_path.empty() || name_or_path == DEFAULT_MESH_NAME) return load_default_mesh(warnings);
  return read_mesh(std::filesystem::path(std::string(name_or_path)), warnings);
}

TriangleSurface load_render_surface(std::string_view name_or_path) {
  if (name_or_path == DEFAULT_MESH_NAME) {
    return parse_obj(resources::frog_surface_obj_text(), "embedded:frog_surface.obj");
  }
  return read_obj(std::filesystem::path(std::string(name_or_path)));
}

}  // namespace tissue
