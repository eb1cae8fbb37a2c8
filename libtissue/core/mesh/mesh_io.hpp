// Mesh readers: Vega .veg, TetGen .node/.ele and Gmsh .msh 4.1 (ASCII), plus Vega .bou
// fixed-vertex lists and Wavefront .obj render surfaces. Every reader checks what it reads (see
// validate_tets) and throws MeshError naming file, line and element; inverted tets are re-oriented
// with a warning.
#pragma once

#include "core/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tissue {

/// The largest file a reader reads (.veg, .node/.ele, .msh, .bou, .obj) [bytes]: the readers hold
/// the whole text, and their counts and reservations are bounded by it. 1 GiB (the 52k-tet organ's .veg is
/// 2 MB).
inline constexpr std::size_t MAX_MESH_FILE_BYTES = std::size_t{1} << 30;

/// The largest absolute coordinate a reader takes, in the file's unit (metres for the engine; a mesh
/// in millimetres fits too): beyond it volumes, masses and the surface tree's bounds overflow.
inline constexpr double MAX_ABS_COORDINATE = 1e6;

/// Non-fatal findings while loading (e.g. "file:line: tet 12 inverted, re-oriented").
struct MeshWarnings {
  std::vector<std::string> messages;
};

/// Vega .veg: *VERTICES / *ELEMENTS TET, 1-indexed, '#' comments. Regions (issue 25): `*MATERIAL
/// name` then `ENU, density, E, nu`; `*SET name` then element numbers; `*REGION` then `set,
/// material` lines (the set `allElements` is predefined): each region is named by its set and has
/// that material. Refused with the line: an unknown set or material, an element in two regions or
/// (when there are regions) in none, a material out of range, a type other than ENU. Other sections
/// (*INCLUDE, ...) are skipped, so an *INCLUDE'd file is not read.
TetMesh read_veg(const std::filesystem::path& path, MeshWarnings* warnings = nullptr);
/// Same, from text already in memory; `source_name` is used in messages in place of a file name.
TetMesh parse_veg(std::string_view text, const std::string& source_name, MeshWarnings* warnings = nullptr);

/// TetGen: `path` is the .node file (or the .ele file, or the common stem); the other is found beside it.
/// Index base (0 or 1) is taken from the first vertex index in the .node file, as TetGen does.
/// A .ele with attributes: the first is the tet's region (tetgen -A), named by its whole number.
TetMesh read_tetgen(const std::filesystem::path& path, MeshWarnings* warnings = nullptr);
/// Same, from the two files' text already in memory (the names are used in messages).
TetMesh parse_tetgen(std::string_view node_text, std::string_view ele_text, const std::string& node_name,
                     const std::string& ele_name, MeshWarnings* warnings = nullptr);

/// Gmsh .msh 4.1 ASCII: $Nodes and $Elements (type 4 = 4-node tet); other element types are ignored.
/// Regions: the physical groups of the tets' volumes ($Entities), named by $PhysicalNames or else by
/// their tag; a volume in two groups, or (when there are groups) in none, is refused with the line.
TetMesh read_gmsh(const std::filesystem::path& path, MeshWarnings* warnings = nullptr);
TetMesh parse_gmsh(std::string_view text, const std::string& source_name, MeshWarnings* warnings = nullptr);

/// A closed triangle mesh [m], triangles wound outward (right-hand rule): a render surface (issue 22).
struct TriangleSurface {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<std::array<int, 3>> triangles;
  std::string source_name = "render surface";  ///< where it was read from, for messages
};

/// Wavefront OBJ: `v x y z` and `f a b c ...` (1-based, negative indices relative to the vertices
/// read so far, `a/t/n` forms take the vertex); a face of more than 3 corners is fanned; other
/// records and '#' comments are skipped. Throws MeshError naming the file, line and element for: a
/// coordinate that is not a finite number, an index out of range, a face with fewer than 3 or
/// repeated corners, an edge shared by more than two triangles (not manifold) or by one (not
/// closed), an edge two triangles run the same way (not consistently oriented), or no triangle.
TriangleSurface read_obj(const std::filesystem::path& path);
TriangleSurface parse_obj(std::string_view text, const std::string& source_name);

/// Dispatches on the extension: .veg, .node/.ele, .msh.
TetMesh read_mesh(const std::filesystem::path& path, MeshWarnings* warnings = nullptr);

/// Vega .bou: 1-indexed vertex ids separated by commas/whitespace; returns sorted unique 0-based ids.
/// Throws MeshError for ids outside [1, vertex_count].
std::vector<int> read_bou(const std::filesystem::path& path, int vertex_count);
std::vector<int> parse_bou(std::string_view text, int vertex_count, const std::string& source_name);

/// Checks applied by every reader (exposed for tests and for meshes built in code):
/// - NaN/Inf coordinates, or beyond +-MAX_ABS_COORDINATE -> MeshError (line of the vertex);
/// - vertex index outside [0, vertex_count) -> MeshError;
/// - a tet with a repeated vertex, or |volume| <= 1e-12 * (bounding-box diagonal)^3 -> MeshError ("zero-volume");
/// - two tets with the same vertex set -> MeshError ("duplicate of element k");
/// - a face shared by more than two tets -> MeshError ("overlapping elements");
/// - negative volume -> vertices 2 and 3 swapped, warning (after 100 such warnings, one summary line);
/// - vertices used by no tet -> one warning (they would get no mass).
/// `vertex_lines` / `element_lines` give the source line of each vertex / tet (may be empty);
/// `index_base` is the file's own numbering base, used only to print element numbers as in the file.
void validate_tets(TetMesh& mesh, const std::string& source_name, const std::vector<int>& vertex_lines,
                   const std::vector<int>& element_lines, int index_base, MeshWarnings* warnings);

}  // namespace tissue
