#include "geometry/obj_io.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>
#include <vector>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "geometry/polygon_triangulation.h"
#include "geometry/text_parsing.h"

namespace subflow::geometry {

TriangleMesh ParseObj(const std::string& text, const std::string& source) {
  std::vector<double> positions;
  PolygonFaces faces;
  std::vector<int> face_lines;  // line of each face, for index errors found at the end
  std::vector<int> corners;
  size_t pos = 0;
  int line_number = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string_view line = std::string_view(text).substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const size_t comment = line.find('#');
    if (comment != std::string_view::npos) line = line.substr(0, comment);
    const std::vector<std::string_view> tokens = SplitTokens(line);
    if (tokens.empty()) continue;
    const std::string where = "line " + std::to_string(line_number);
    if (tokens[0] == "v") {
      const int vertex = static_cast<int>(positions.size() / 3);
      if (tokens.size() < 4)
        ThrowError(source, where + " (vertex " + std::to_string(vertex) + ")",
                   "expected \"v x y z\"");
      if (vertex == std::numeric_limits<int>::max())
        ThrowError(source, where, "more than 2^31 − 1 vertices");
      for (int axis = 0; axis < 3; ++axis) {
        double value = 0.0;
        if (!ParseDouble(tokens[1 + axis], &value))
          ThrowError(source, where + " (vertex " + std::to_string(vertex) + ")",
                     "\"" + std::string(tokens[1 + axis]) + "\" is not a number");
        if (!std::isfinite(value))
          ThrowError(source, where + " (vertex " + std::to_string(vertex) + ")",
                     std::string("coordinate ") + "xyz"[axis] + " is " +
                         (std::isnan(value) ? "NaN" : "infinite") + " (expected a finite number)");
        positions.push_back(value);
      }
    } else if (tokens[0] == "f") {
      const int face = faces.face_count();
      const std::string field = where + " (face " + std::to_string(face) + ")";
      const int count = static_cast<int>(tokens.size()) - 1;
      if (count < 3)
        ThrowError(source, field,
                   "has " + std::to_string(count) + " vertices; expected a polygon of at least 3");
      if (count > kMaxPolygonCorners)
        ThrowError(source, field,
                   "has " + std::to_string(count) + " vertices; expected at most " +
                       std::to_string(kMaxPolygonCorners));
      const int vertex_count = static_cast<int>(positions.size() / 3);
      corners.clear();
      for (int k = 1; k <= count; ++k) {
        const std::string_view corner = tokens[k].substr(0, tokens[k].find('/'));
        long long index = 0;
        if (!ParseInteger(corner, &index) || index == 0)
          ThrowError(source, field,
                     "\"" + std::string(tokens[k]) +
                         "\" is not a vertex index (expected a non-zero integer)");
        // Negative indices count back from the latest vertex; positive ones may only be
        // checked once every vertex has been read.
        const long long zero_based = index < 0 ? vertex_count + index : index - 1;
        if (zero_based < 0)
          ThrowError(source, field,
                     "relative vertex index " + std::to_string(index) +
                         " points before the first vertex (only " + std::to_string(vertex_count) +
                         " vertices defined so far)");
        if (zero_based >= std::numeric_limits<int>::max())
          ThrowError(source, field, "vertex index " + std::to_string(index) + " out of range");
        corners.push_back(static_cast<int>(zero_based));
      }
      faces.Add(corners.data(), count);
      face_lines.push_back(line_number);
    }
    // Everything else (vt, vn, vp, l, p, o, g, s, usemtl, mtllib, ...) carries no
    // geometry subflow uses.
  }

  TriangleMesh mesh;
  const int n = static_cast<int>(positions.size() / 3);
  const int m = faces.face_count();
  if (n == 0) ThrowError(source, "vertices", "no \"v\" statement (expected a non-empty mesh)");
  if (m == 0) ThrowError(source, "faces", "no \"f\" statement (expected a polygon mesh)");
  mesh.V = Eigen::Map<const Positions>(positions.data(), n, 3);
  for (int f = 0; f < m; ++f)
    for (int c = faces.starts[f]; c < faces.starts[f + 1]; ++c)
      if (faces.corners[c] >= n)
        ThrowError(source,
                   "line " + std::to_string(face_lines[f]) + " (face " + std::to_string(f) + ")",
                   "vertex index " + std::to_string(faces.corners[c] + 1) + " out of range [1, " +
                       std::to_string(n) + "] (1-based)");
  int polygons = 0;
  mesh.F = TriangulatePolygons(faces, mesh.V, &polygons);
  if (polygons > 0)
    spdlog::warn("{}: {} of {} faces have more than 3 corners; triangulated into {} triangles",
                 source, polygons, m, mesh.face_count());
  return mesh;
}

void WriteObj(std::ostream& out, const TriangleMesh& mesh, const std::string& source) {
  std::string text = "# written by subflow\n";
  char line[96];
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (!mesh.V.row(v).allFinite())
      ThrowError(source, "vertex " + std::to_string(v),
                 "non-finite coordinate (refusing to write it)");
    std::snprintf(line, sizeof(line), "v %.17g %.17g %.17g\n", mesh.V(v, 0), mesh.V(v, 1),
                  mesh.V(v, 2));
    text += line;
  }
  for (int f = 0; f < mesh.face_count(); ++f) {
    std::snprintf(line, sizeof(line), "f %d %d %d\n", mesh.F(f, 0) + 1, mesh.F(f, 1) + 1,
                  mesh.F(f, 2) + 1);
    text += line;
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

}  // namespace subflow::geometry
