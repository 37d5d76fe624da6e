// Internal to geometry/: the per-vertex pieces that the frame computation
// (local_frames.cpp) and the fused synthesis step (refine_and_add_details.cpp) share.
#pragma once

#include <Eigen/Core>

#include "geometry/point_stencil.h"

namespace subflow::geometry::internal {

// Relative size of |t1 × t2| against |t1||t2| below which a frame counts as degenerate.
constexpr double kDegenerateSine = 1e-12;

// Both tangents of vertex v from the two-channel tangent stencil. Regular vertices
// (pattern key 6, the vast majority on fine levels) use the closed form of the masks
// cos/sin(2πj/6) = (1, ½, −½, −1, −½, ½) / (0, h, h, 0, −h, −h), h = √3/2.
inline void TangentsAt(const PointStencil& stencil, int regular_offset, const double* points,
                       int v, double* a, double* b) {
  const int* offsets = stencil.offsets();
  const int* columns = stencil.columns();
  const int weight_offset = stencil.weight_offsets()[v];
  if (weight_offset == regular_offset) {
    const int* ring = columns + offsets[v];
    const double* p0 = points + 3 * static_cast<Eigen::Index>(ring[0]);
    const double* p1 = points + 3 * static_cast<Eigen::Index>(ring[1]);
    const double* p2 = points + 3 * static_cast<Eigen::Index>(ring[2]);
    const double* p3 = points + 3 * static_cast<Eigen::Index>(ring[3]);
    const double* p4 = points + 3 * static_cast<Eigen::Index>(ring[4]);
    const double* p5 = points + 3 * static_cast<Eigen::Index>(ring[5]);
    const double h = 0.8660254037844386;  // √3/2
    for (int k = 0; k < 3; ++k) {
      a[k] = (p0[k] - p3[k]) + 0.5 * ((p1[k] + p5[k]) - (p2[k] + p4[k]));
      b[k] = h * ((p1[k] + p2[k]) - (p4[k] + p5[k]));
    }
    return;
  }
  const double* w = stencil.weights() + weight_offset;
  a[0] = a[1] = a[2] = b[0] = b[1] = b[2] = 0.0;
  for (int i = offsets[v]; i < offsets[v + 1]; ++i, w += 2) {
    const double* p = points + 3 * static_cast<Eigen::Index>(columns[i]);
    for (int k = 0; k < 3; ++k) {
      a[k] += w[0] * p[k];
      b[k] += w[1] * p[k];
    }
  }
}

}  // namespace subflow::geometry::internal
