// Private to core/render: the edge keys CutRenderSurface's files share (cut_render_surface.cpp,
// cut_render_split.cpp, cut_render_caps.cpp).
#pragma once

#include <algorithm>

namespace tissue::cut_render_detail {

// An edge as one integer: (u, v) directed, and the same for either direction (lower, higher).
inline long long directed_key(int u, int v) { return (static_cast<long long>(u) << 32) | static_cast<unsigned int>(v); }
inline long long edge_key(int u, int v) { return directed_key(std::min(u, v), std::max(u, v)); }

}  // namespace tissue::cut_render_detail
