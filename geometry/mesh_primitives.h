// Small closed and open triangle meshes built in code (see also geometry/icosphere.h): test fixtures, benchmark inputs and
// base meshes for synthetic data. All faces are counter-clockwise seen from outside
// (closed meshes) or from +z (open patches).
#pragma once

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Regular polyhedra inscribed in the unit sphere (every vertex at distance 1).
TriangleMesh Tetrahedron();   // 4 vertices of valence 3
TriangleMesh Octahedron();    // 6 vertices of valence 4
TriangleMesh Icosahedron();   // 12 vertices of valence 5

// Double pyramid over a regular `sides`-gon in the plane z = 0 (radius 1), apexes at
// z = ±height: two apexes of valence `sides` (≥ 3), equator vertices of valence 4.
TriangleMesh Bipyramid(int sides, double height = 1.0);

// Open planar patch [0, nx] × [0, ny] (unit cells, z = 0), each cell split into two
// triangles along a diagonal that alternates like a checkerboard: interior vertices have
// valence 8 (i + j even) or 4 (i + j odd); boundary vertices have 1 to 4 faces.
TriangleMesh GridPatch(int nx, int ny);

}  // namespace subflow::geometry
