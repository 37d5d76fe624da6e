// Per-vertex error maps of a reconstruction against its ground truth (`subflow eval
// --error-maps DIR`): where on the surface the figures of vision/evaluation.h come from.
//
// For one frame, with R the result mesh and T the true mesh:
//   result side, per vertex x of R:  c = the closest point of T,
//     error    = ±|x − c|, > 0 when x is outside the volume of T: the result lies outside
//                the truth (a bulge, a lid over a hollow); < 0 inside (a dent, a plate
//                too thin)
//     views    = the cameras that see c (vision/evaluation_visibility.h)
//   truth side, per vertex t of T:   r = the closest point of R,
//     error    = ±|r − t|, > 0 when t is inside the volume of R: the result passes outside
//                the truth there (a hollow it does not enter, a plate it keeps fat)
//     views    = the cameras that see t.
// The side is the ray-parity inside test of the other mesh (geometry::ClosestPointTree::
// Side), not the direction of the nearest point: a vertex deep in a hollow that the result
// caps has its nearest result point through the hollow's wall, on the far side. Where the
// other mesh bounds no volume (open, or not a manifold), and for points on it, the sign
// is that of (x − c)·n_T (n_T the normal of c's face), resp. (r − t)·n_t (the true vertex
// normal).
// The truth side shows what the result misses (completeness), the result side where its
// surface is wrong (accuracy). Views are −1 when no cameras are given.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::vision {

struct SurfaceErrorMap {
  Eigen::VectorXd error;  // signed distance per vertex (see the file comment)
  Eigen::VectorXi views;  // cameras that see the vertex's true point (−1: not computed)
};

struct FrameErrorMaps {
  SurfaceErrorMap result;  // per vertex of the result mesh
  SurfaceErrorMap truth;   // per vertex of the true mesh
};

// `visibility_tolerance`: depth tolerance of the visibility test (world units, > 0 when
// cameras are given). Throws subflow::Error (via the closest-point trees) for meshes
// without area.
FrameErrorMaps ComputeErrorMaps(const geometry::TriangleMesh& truth, const geometry::TriangleMesh& result,
                                const std::vector<Camera>& cameras, double visibility_tolerance);

}  // namespace subflow::vision
