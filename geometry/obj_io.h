// The Wavefront OBJ side of mesh I/O; ReadMesh/WriteMesh in geometry/mesh_io.h dispatch
// here by extension.
//
// Reading keeps "v x y z" (a 4th value w and trailing vertex colours are ignored) and
// "f a b c ..." whose corners may be written i, i/t, i//n or i/t/n; indices are 1-based, or
// negative = relative to the last vertex defined so far (-1 is the latest). Comments (#),
// vt, vn, vp, l, p, o, g, s, usemtl, mtllib and unknown statements are ignored.
// Polygons (more than 3 corners) are triangulated (geometry/polygon_triangulation.h) with
// a warning. OBJ holds no per-vertex scalar properties.
#pragma once

#include <ostream>
#include <string>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Parses the OBJ document `text`; `source` names it in errors. Throws subflow::Error on
// faces of fewer than 3 or more than kMaxPolygonCorners corners, indices 0 or out of
// range, malformed or non-finite numbers, and documents with no vertex or no face. Does
// not check manifoldness.
TriangleMesh ParseObj(const std::string& text, const std::string& source);

// Writes "v x y z" with 17 significant digits (doubles round-trip exactly) and
// "f a b c" with 1-based indices.
void WriteObj(std::ostream& out, const TriangleMesh& mesh, const std::string& source);

}  // namespace subflow::geometry
