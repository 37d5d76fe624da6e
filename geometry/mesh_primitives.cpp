#include "geometry/mesh_primitives.h"

#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "core/error.h"

namespace subflow::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Orients every face of a convex polyhedron around the origin outwards.
void OrientOutwards(TriangleMesh* mesh) {
  for (int f = 0; f < mesh->face_count(); ++f) {
    const Eigen::Vector3d a = mesh->V.row(mesh->F(f, 0)), b = mesh->V.row(mesh->F(f, 1)),
                          c = mesh->V.row(mesh->F(f, 2));
    if ((b - a).cross(c - a).dot(a + b + c) < 0) std::swap(mesh->F(f, 1), mesh->F(f, 2));
  }
}

void NormalizeRows(Positions* V) {
  for (Eigen::Index v = 0; v < V->rows(); ++v) V->row(v).normalize();
}

}  // namespace

TriangleMesh Tetrahedron() {
  TriangleMesh mesh;
  mesh.V.resize(4, 3);
  mesh.V << 1, 1, 1, 1, -1, -1, -1, 1, -1, -1, -1, 1;
  NormalizeRows(&mesh.V);
  mesh.F.resize(4, 3);
  mesh.F << 0, 1, 2, 0, 1, 3, 0, 2, 3, 1, 2, 3;
  OrientOutwards(&mesh);
  return mesh;
}

TriangleMesh Octahedron() {
  TriangleMesh mesh;
  mesh.V.resize(6, 3);
  mesh.V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  mesh.F.resize(8, 3);
  mesh.F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  OrientOutwards(&mesh);
  return mesh;
}

TriangleMesh Icosahedron() {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  TriangleMesh mesh;
  mesh.V.resize(12, 3);
  mesh.V << -1, phi, 0, 1, phi, 0, -1, -phi, 0, 1, -phi, 0,  //
      0, -1, phi, 0, 1, phi, 0, -1, -phi, 0, 1, -phi,          //
      phi, 0, -1, phi, 0, 1, -phi, 0, -1, -phi, 0, 1;
  NormalizeRows(&mesh.V);
  mesh.F.resize(20, 3);
  mesh.F << 0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11,  //
      1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,          //
      3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9,              //
      4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1;
  OrientOutwards(&mesh);
  return mesh;
}

TriangleMesh Bipyramid(int sides, double height) {
  if (sides < 3) ThrowError("Bipyramid", "sides", "expected ≥ 3, got " + std::to_string(sides));
  TriangleMesh mesh;
  mesh.V.resize(sides + 2, 3);
  for (int i = 0; i < sides; ++i) {
    const double angle = 2.0 * kPi * i / sides;
    mesh.V.row(i) << std::cos(angle), std::sin(angle), 0.0;
  }
  mesh.V.row(sides) << 0.0, 0.0, height;
  mesh.V.row(sides + 1) << 0.0, 0.0, -height;
  mesh.F.resize(2 * sides, 3);
  for (int i = 0; i < sides; ++i) {
    const int next = (i + 1) % sides;
    mesh.F.row(i) << i, next, sides;               // counter-clockwise seen from +z
    mesh.F.row(sides + i) << next, i, sides + 1;   // seen from −z
  }
  return mesh;
}

TriangleMesh GridPatch(int nx, int ny) {
  if (nx < 1 || ny < 1)
    ThrowError("GridPatch", "size", "expected at least one cell in each direction");
  TriangleMesh mesh;
  mesh.V.resize((nx + 1) * (ny + 1), 3);
  auto index = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.V.row(index(i, j)) << i, j, 0.0;
  mesh.F.resize(2 * nx * ny, 3);
  int f = 0;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1),
                d = index(i, j + 1);
      if ((i + j) % 2 == 0) {  // diagonal a–c
        mesh.F.row(f++) << a, b, c;
        mesh.F.row(f++) << a, c, d;
      } else {  // diagonal b–d
        mesh.F.row(f++) << a, b, d;
        mesh.F.row(f++) << b, c, d;
      }
    }
  }
  return mesh;
}

}  // namespace subflow::geometry
