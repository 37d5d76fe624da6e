#include "geometry/limit_tessellation.h"

#include <string>

#include "core/error.h"

namespace subflow::geometry {
namespace {

// (u, v) of the point with barycentric weight 1 − t on corner k and t on corner k + 1.
FaceSample EdgePoint(int face, int k, double t) {
  double w[3] = {0.0, 0.0, 0.0};
  w[k] = 1.0 - t;
  w[(k + 1) % 3] = t;
  return {face, w[1], w[2]};
}

}  // namespace

LimitTessellation TessellateLimitSurface(const MeshTopology& topology, int density) {
  if (density < 1)
    ThrowError("limit tessellation", "density",
               std::to_string(density) + " (expected >= 1 triangles per face edge)");
  const int m = density;
  LimitTessellation result;
  std::vector<FaceSample>& samples = result.samples;

  result.vertex_sample.assign(topology.vertex_count(), -1);
  for (int v = 0; v < topology.vertex_count(); ++v) {
    if (topology.RingFaces(v).size() == 0) continue;
    const int f = topology.RingFaces(v)[0];
    int k = 0;
    while (topology.HalfedgeSource(3 * f + k) != v) ++k;
    result.vertex_sample[v] = static_cast<int>(samples.size());
    samples.push_back({f, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0});
  }
  const int edge_base = static_cast<int>(samples.size());
  for (int e = 0; e < topology.edge_count(); ++e) {
    const int h = topology.EdgeHalfedge(e);
    for (int s = 1; s < m; ++s) samples.push_back(EdgePoint(h / 3, h % 3, double(s) / m));
  }
  const int face_base = static_cast<int>(samples.size());
  const int interior_per_face = (m - 1) * (m - 2) / 2;
  for (int f = 0; f < topology.face_count(); ++f)
    for (int j = 1; j < m; ++j)
      for (int i = 1; i + j < m; ++i) samples.push_back({f, double(i) / m, double(j) / m});

  result.faces.resize(static_cast<Eigen::Index>(topology.face_count()) * m * m, 3);
  int out = 0;
  std::vector<int> lattice((m + 1) * (m + 1), -1);  // sample of lattice point (i, j)
  auto at = [&](int i, int j) -> int& { return lattice[j * (m + 1) + i]; };
  for (int f = 0; f < topology.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int corner_sample = result.vertex_sample[topology.HalfedgeSource(3 * f + k)];
      const int e = topology.FaceEdge(f, k);
      const bool forward = topology.EdgeHalfedge(e) == 3 * f + k;
      for (int s = 0; s < m; ++s) {
        // Point s of edge k from corner k, as a lattice point of this face.
        const int i = k == 0 ? s : k == 1 ? m - s : 0;
        const int j = k == 0 ? 0 : k == 1 ? s : m - s;
        at(i, j) = s == 0 ? corner_sample
                          : edge_base + e * (m - 1) + (forward ? s - 1 : m - 1 - s);
      }
    }
    int next = face_base + f * interior_per_face;
    for (int j = 1; j < m; ++j)
      for (int i = 1; i + j < m; ++i) at(i, j) = next++;
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i + j < m; ++i) {
        result.faces.row(out++) << at(i, j), at(i + 1, j), at(i, j + 1);
        if (i + j + 2 <= m) result.faces.row(out++) << at(i + 1, j), at(i + 1, j + 1), at(i, j + 1);
      }
    }
  }
  return result;
}

}  // namespace subflow::geometry
