// The icosphere: a regular icosahedron whose faces are split 1→4 `subdivisions` times,
// new vertices pushed onto the sphere. 10·4^s + 2 vertices, 20·4^s faces (s = 6 gives
// Blender's 10242 / 20480). Faces are counter-clockwise seen from outside.
#pragma once

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Icosphere of `radius` centred at the origin; deterministic vertex order: the 12
// icosahedron vertices first, then each level's edge midpoints in order of first use.
// Throws subflow::Error when subdivisions is outside [0, 8] or radius ≤ 0.
TriangleMesh MakeIcosphere(int subdivisions, double radius = 1.0);

}  // namespace subflow::geometry
