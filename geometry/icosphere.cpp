#include "geometry/icosphere.h"

#include <cmath>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/error.h"

namespace subflow::geometry {

TriangleMesh MakeIcosphere(int subdivisions, double radius) {
  if (subdivisions < 0 || subdivisions > 8)
    ThrowError("MakeIcosphere", "subdivisions",
               "expected 0..8, got " + std::to_string(subdivisions));
  if (!(radius > 0.0) || !std::isfinite(radius))
    ThrowError("MakeIcosphere", "radius", "expected a finite positive radius");
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> vertices = {
      {-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
      {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (auto& v : vertices) v.normalize();
  std::vector<Eigen::Vector3i> faces = {
      {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::unordered_map<long long, int> midpoint_of_edge;
    auto midpoint = [&](int a, int b) {
      const long long key = static_cast<long long>(std::min(a, b)) * (1LL << 32) + std::max(a, b);
      const auto found = midpoint_of_edge.find(key);
      if (found != midpoint_of_edge.end()) return found->second;
      vertices.push_back((vertices[a] + vertices[b]).normalized());
      const int index = static_cast<int>(vertices.size()) - 1;
      midpoint_of_edge.emplace(key, index);
      return index;
    };
    std::vector<Eigen::Vector3i> refined;
    refined.reserve(4 * faces.size());
    for (const auto& f : faces) {
      const int ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      refined.push_back({f[0], ab, ca});
      refined.push_back({f[1], bc, ab});
      refined.push_back({f[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    faces.swap(refined);
  }
  TriangleMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t i = 0; i < vertices.size(); ++i) mesh.V.row(i) = radius * vertices[i].transpose();
  mesh.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) mesh.F.row(i) = faces[i].transpose();
  return mesh;
}

}  // namespace subflow::geometry
