// Vertices that no face references: legal in PLY and OBJ (tools leave them after deleting
// faces), but a subdivision base mesh needs every vertex to be a corner.
#pragma once

#include <vector>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Drops the vertices of `mesh` that no face references: the others keep their order and
// F is renumbered. Returns the number dropped; `old_to_new` (optional, #V before) receives
// each old vertex's new index, or −1 for a dropped one. F's indices must be in [0, #V).
int RemoveUnusedVertices(TriangleMesh* mesh, std::vector<int>* old_to_new = nullptr);

}  // namespace subflow::geometry
