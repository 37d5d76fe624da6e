// Reading and writing triangle meshes: PLY (ascii, binary little/big endian) and OBJ.
// Readers validate what they read and throw subflow::Error naming the file, the element
// (line, vertex, face) and what was expected: faces of fewer than 3 corners, indices out
// of range, NaN/Inf coordinates, truncated data, unknown formats. Polygon faces are
// triangulated with a warning (geometry/polygon_triangulation.h). Manifoldness is checked by
// MeshTopology (ReadMesh does it when `require_manifold` is set).
// Writers never leave a half-written file: they write to "<path>.tmp" and rename.
#pragma once

#include <map>
#include <vector>
#include <string>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Extra per-vertex scalar properties (e.g. "vx", "vy", "vz" for scene flow), each a
// column of #V values, written as float after x y z in the order of the map's keys
// unless an explicit order is given.
struct VertexProperties {
  std::vector<std::string> names;           // order in the file
  std::map<std::string, Eigen::VectorXd> values;  // name → #V values
};

struct MeshReadOptions {
  bool require_manifold = true;  // check with MeshTopology; throws on non-manifold input
};

// Reads .ply or .obj (by extension, case-insensitive). Polygons with more than three
// vertices are triangulated (subflow works on triangle meshes), with a warning.
TriangleMesh ReadMesh(const std::string& path, const MeshReadOptions& options = {},
                      VertexProperties* properties = nullptr);

// kBinaryLittleEndianDouble stores x y z and the properties as double: the exact values,
// for files a later run reads back (the stage folders of docs/stages.md).
enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryLittleEndianDouble };

// Writes .ply (binary little-endian by default: float x y z [+ properties], faces as
// "uchar int" lists) or .obj, by extension. The directory must exist; OBJ cannot hold
// properties (non-empty properties with a .obj path are an error); non-finite positions
// and out-of-range indices are refused. Formats: geometry/ply_io.h, geometry/obj_io.h.
// Written through core/atomic_file.h (".<name>.partial", renamed when complete); throws
// subflow::Interrupted before starting once SIGINT / SIGTERM arrived (core/interrupt.h).
void WriteMesh(const std::string& path, const TriangleMesh& mesh,
               const VertexProperties* properties = nullptr,
               PlyFormat ply_format = PlyFormat::kBinaryLittleEndian);

}  // namespace subflow::geometry
