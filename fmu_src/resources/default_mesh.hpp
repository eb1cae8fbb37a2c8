// The embedded default specimen: the project's frog (meshes/frog.veg, ~800 vertices, ~2300 tets).
#pragma once

#include "core/mesh/mesh_io.hpp"

#include <string_view>

namespace tissue::resources {

/// The text of meshes/frog.veg as it was at build time.
std::string_view frog_veg_text();
/// The text of meshes/frog_surface.obj (the frog's render surface) as it was at build time.
std::string_view frog_surface_obj_text();

}  // namespace tissue::resources

namespace tissue {

/// Name used in messages and by --mesh to mean the embedded frog.
inline constexpr std::string_view DEFAULT_MESH_NAME = "frog";

/// Parses the embedded frog.
TetMesh load_default_mesh(MeshWarnings* warnings = nullptr);

/// `name_or_path` == "frog" (or empty) gives the embedded frog; anything else is read from disk.
TetMesh load_mesh(std::string_view name_or_path, MeshWarnings* warnings = nullptr);

/// A render surface's name meaning "none: draw the tet skin".
inline constexpr std::string_view NO_RENDER_SURFACE = "none";
/// `name_or_path` == "frog" gives the embedded frog's render surface; anything else is read from disk
/// (OBJ). Throws MeshError naming the file and the element.
TriangleSurface load_render_surface(std::string_view name_or_path);

}  // namespace tissue
