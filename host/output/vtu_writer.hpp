// vtu_writer.hpp - one SurfaceFrame as a VTK XML UnstructuredGrid (.vtu) of triangles, for
// ParaView. The piece's arrays in VTK's "binary" format (base64 of the exact values), the few field
// values in ASCII (shortest round-trip, std::to_chars, locale-independent): equal frames give
// byte-identical files.
#pragma once

#include "output/surface_frame.hpp"

#include <filesystem>
#include <string>

namespace tissue::host {

/**
 * The .vtu document of @p frame (VTK XML file format, "UnstructuredGrid", version 0.1):
 * - Points: Float64 x y z per vertex, every vertex of the frame (unreferenced ones included, so
 *   that point ids are the FMU's surface.vertexPositions rows), binary;
 * - Cells: one VTK_TRIANGLE (type 5) per triangle, connectivity and end offsets as Int32, binary;
 * - CellData "cut_face" (UInt8, binary): 0 for the first mesh_triangle_count triangles, 1 for cut faces;
 * - FieldData: "TimeValue" (Float64, s); with has_tool "tool_tip_m", "tool_handle_m" (Float64 x3)
 *   and "tool_mode" (Int32); with contact_active "contact_point_m" (Float64 x3) and "force_n"
 *   (Float64 x3, the force on the tool).
 * Throws OutputError (validate_surface_frame) for an invalid frame.
 */
[[nodiscard]] std::string vtu_document(const SurfaceFrame& frame);

/// Writes vtu_document(@p frame) to @p path (replacing it whole); throws OutputError.
void write_vtu(const std::filesystem::path& path, const SurfaceFrame& frame);

}  // namespace tissue::host
