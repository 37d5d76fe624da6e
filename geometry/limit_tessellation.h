// A regular tessellation of the limit surface: every control face split into density²
// small triangles at the barycentric points (i/m, j/m), i + j ≤ m (m = density), with the
// samples shared along edges and at vertices listed once, so the tessellation is a
// watertight mesh with the control mesh's topology (closed if it is closed). Evaluate it
// with LoopLimitEvaluator::LimitMatrix(samples): s = L c gives the tessellation's vertex
// positions (what OUTPUT.md's meshes/<frame>.ply hold), with the same vertex order and
// faces for every frame.
//
// Sample order:
//   [0, #V)                 one per control vertex v (v's limit position), in vertex order;
//                           a vertex referenced by no face gets no sample, and the samples
//                           of later vertices move down (see vertex_sample);
//   then (m − 1) per edge   in MeshTopology edge order, running from EdgeVertex(e, 0) to
//                           EdgeVertex(e, 1), evaluated on the face of EdgeHalfedge(e);
//   then (m−1)(m−2)/2 per face   the interior points, face by face, i (u) fastest
//                           within rows of increasing j (v).
// Faces: m² per control face, face by face, counter-clockwise like the control face.
#pragma once

#include <vector>

#include "geometry/limit_evaluation.h"
#include "geometry/mesh_topology.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct LimitTessellation {
  std::vector<FaceSample> samples;  // one per tessellation vertex
  Faces faces;                      // density² × #F triangles over sample indices
  std::vector<int> vertex_sample;   // control vertex → its sample, −1 if unreferenced
};

// Throws subflow::Error if density < 1.
LimitTessellation TessellateLimitSurface(const MeshTopology& topology, int density);

}  // namespace subflow::geometry
