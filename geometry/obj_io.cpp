#include "geometry/obj_io.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "geometry/text_parsing.h"

namespace subflow::geometry {

TriangleMesh ParseObj(const std::string& text, const std::string& source) {
  std::vector<double> positions;
  std::vector<int> corners;
  std::vector<int> corner_lines;  // line of each face, for index errors found at the end
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
      const int face = static_cast<int>(corner_lines.size());
      const std::string field = where + " (face " + std::to_string(face) + ")";
      if (tokens.size() != 4)
        ThrowError(source, field,
                   "has " + std::to_string(tokens.size() - 1) +
                       " vertices; expected 3 (subflow reads triangle meshes only)");
      const int vertex_count = static_cast<int>(positions.size() / 3);
      for (int k = 1; k <= 3; ++k) {
        const std::string_view corner = tokens[k].substr(0, tokens[k].find('/'));
        long long index = 0;
        const auto result = std::from_chars(corner.data(), corner.data() + corner.size(), index);
        if (result.ec != std::errc() || result.ptr != corner.data() + corner.size() || index == 0)
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
        if (zero_based > std::numeric_limits<int>::max())
          ThrowError(source, field, "vertex index " + std::to_string(index) + " out of range");
        corners.push_back(static_cast<int>(zero_based));
      }
      corner_lines.push_back(line_number);
    }
    // Everything else (vt, vn, vp, l, p, o, g, s, usemtl, mtllib, ...) carries no
    // geometry subflow uses.
  }

  TriangleMesh mesh;
  const int n = static_cast<int>(positions.size() / 3);
  const int m = static_cast<int>(corner_lines.size());
  if (n == 0) ThrowError(source, "vertices", "no \"v\" statement (expected a non-empty mesh)");
  if (m == 0) ThrowError(source, "faces", "no \"f\" statement (expected a triangle mesh)");
  mesh.V = Eigen::Map<const Positions>(positions.data(), n, 3);
  mesh.F.resize(m, 3);
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = corners[3 * f + k];
      if (v >= n)
        ThrowError(source,
                   "line " + std::to_string(corner_lines[f]) + " (face " + std::to_string(f) + ")",
                   "vertex index " + std::to_string(v + 1) + " out of range [1, " +
                       std::to_string(n) + "] (1-based)");
      mesh.F(f, k) = v;
    }
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
