// Private to core/fem: what DeformableBody::enrich's stages share (deformable_body_enrich.cpp makes
// the cut tets and grows the system, deformable_body_ghosts.cpp finds which ghost each piece uses).
#pragma once

#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <vector>

namespace tissue {

// What enrich_pieces' stages share: the cut tets to make and the new ghost rows, and plan_ghosts'
// scratch, reused vertex after vertex.
struct DeformableBody::EnrichBatch {
  // A cut tet to be made: for a cut of the batch, or to give an existing one other ghosts.
  struct Plan {
    int tet = -1;
    int old = -1;  // the live cut tet it replaces, or -1
    bool from_cut = true;
    CutTetGeometry geometry;
    // per piece and local vertex: ghost row, -1 real, -2 - n the n-th new row, or a held copy
    // (HELD_COPY_FIRST + its index, the batch's new ones after the body's)
    std::vector<std::array<int, 4>> rows;
  };
  // A piece of a tet around a vertex that cuts separate from it.
  struct Node {
    int tet;
    size_t piece;
    size_t local;  // v's local index in the tet
    SeparatingCuts key;
    int candidate;  // the row or held copy it uses now (or its parent used), -1 none
  };
  // A face two tets of a vertex's star share (star indices and the face's rest corners).
  struct StarFace {
    size_t a, b;
    std::array<Eigen::Vector3d, 3> corners;
    double area_threshold;
  };

  std::vector<Plan> plans;
  std::vector<int> plan_of_tet;          // per tet: its plan, or -1
  std::vector<SeparatingCuts> new_rows;  // keys of the rows to create
  std::vector<int> new_row_vertex;
  std::vector<EnrichedDof> new_held;  // the held copies to create
  int old_dofs = 0;  // the enriched unknowns before the batch
  std::vector<Node> nodes;
  std::vector<StarFace> faces;
  std::vector<int> parent_of;              // union-find over a key's nodes, then the star's uncut tets
  std::vector<std::vector<int>> elements;  // per star tet: its elements of the key
};

}  // namespace tissue
