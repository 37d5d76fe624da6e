// The PLY (Polygon File Format, Stanford) side of mesh I/O; ReadMesh/WriteMesh in
// geometry/mesh_io.h dispatch here by extension. Exposed separately so that callers
// holding a PLY document in memory (tests, archives) need no file.
//
// Reading accepts ascii, binary_little_endian and binary_big_endian; every PLY scalar
// type (char/uchar/short/ushort/int/uint/float/double and the int8/uint8/int16/uint16/
// int32/uint32/float32/float64 aliases) for any property; the element "vertex" with
// scalar properties x, y, z (others become VertexProperties, converted to double); the
// element "face" with a list property "vertex_indices" (or "vertex_index") of any
// integer count and index type, each list of 3 or more indices (polygons are triangulated,
// geometry/polygon_triangulation.h, with a warning); any other element or property is
// skipped. An ascii element instance is one line.
#pragma once

#include <ostream>
#include <string>

#include "geometry/mesh_io.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Parses the PLY document `bytes`; `source` (usually the path) names it in errors.
// Throws subflow::Error on a bad header, an unsupported format, truncated data, fewer
// lines than the header announces, element counts the data cannot hold (refused before
// allocating), faces of fewer than 3 or more than kMaxPolygonCorners corners, indices out
// of range, NaN/Inf coordinates. Does not check manifoldness.
TriangleMesh ParsePly(const std::string& bytes, const std::string& source,
                      VertexProperties* properties = nullptr);

// Writes `mesh` as PLY: float x y z [+ properties as float, in properties->names order,
// or the map's key order when names is empty], faces as "list uchar int vertex_indices";
// double instead of float for kBinaryLittleEndianDouble.
// ASCII floats carry 9 significant digits, so both formats store exactly the float
// values. `source` names the destination in errors (property size mismatches).
void WritePly(std::ostream& out, const TriangleMesh& mesh, const VertexProperties* properties,
              PlyFormat format, const std::string& source);

// The property names to write, in order (see WritePly); checks that each has #V values
// and does not collide with x, y, z.
std::vector<std::string> PropertyWriteOrder(const VertexProperties& properties, int vertex_count,
                                            const std::string& source);

}  // namespace subflow::geometry
