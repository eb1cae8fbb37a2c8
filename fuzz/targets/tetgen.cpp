// Door: a TetGen .node/.ele pair (read_tetgen -> parse_tetgen). The input is the .node text, a
// line "@@ele", then the .ele text (a seed's two files joined; see fuzz/README.md). Promise: refused
// with a MeshError, or accepted and steppable.
#include "core/mesh/mesh_io.hpp"
#include "support/accepted_mesh.hpp"

#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue;
  const std::string_view text = fuzz::as_text(data, size);
  constexpr std::string_view SEPARATOR = "\n@@ele\n";
  const std::size_t at = text.find(SEPARATOR);
  const std::string_view node = at == std::string_view::npos ? text : text.substr(0, at);
  const std::string_view ele = at == std::string_view::npos ? std::string_view{} : text.substr(at + SEPARATOR.size());
  return fuzz::mesh_door([&] { return parse_tetgen(node, ele, "fuzz.node", "fuzz.ele"); }, "tetgen");
}
