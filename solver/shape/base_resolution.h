// Adaptive resolution of the shape stage (issue 12 item 3; method §4.1 step 1, §3.4): the
// base mesh T0 and the number of subdivision levels chosen from the subject's detail and
// the images' resolution instead of fixed counts.
//
//   1. B = the reference frame's visual hull simplified until it would leave
//      ε = base_distance_voxels voxels of it, both ways (geometry/simplify.h,
//      max_distance): thin parts and bends keep their faces, smooth regions lose theirs.
//   2. e_B = the projected length of B's edges in pixels: per camera the median over the
//      edges it sees (vision::SurfaceScale), then the median over the cameras. Each level
//      halves the edges, so level L's are about e_B / 2^L.
//   3. L = floor(log2(e_B / finest_edge_pixels)) (0 … 6): the fewest levels whose finest
//      edges are at most 2 · finest_edge_pixels; then
//   4. T0 = the same bounded simplification stopped at N = |B| · (e_B / (t · 2^L))² faces
//      (t = finest_edge_pixels, N ≥ |B|): T0's typical edges become t · 2^L, so the
//      finest edges are about t pixels where the subject is smooth, and finer on the parts
//      the bound kept (with a face budget of N · 4^L ≤ max_finest_faces and
//      |T0| ≤ simplify.max_face_count). The budget is the cost bound: on HD images the
//      finest edges then stay coarser than finest_edge_pixels.
// With base_distance_voxels = 0, T0 is the count-based simplification (target_face_count
// faces) and step 3 picks L from its edges. An explicit `levels` ≥ 0 skips steps 3–4.
#pragma once

#include <string>
#include <vector>

#include "geometry/simplify.h"
#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::solver {

struct ShapeInitOptions;

struct BaseResolution {
  geometry::TriangleMesh base;       // T0
  geometry::SimplifySummary simplify;  // of T0's simplification
  int levels = 0;                    // subdivision levels above T0
  int bound_face_count = 0;          // |B|: faces the distance bound alone kept (0 without a bound)
  double bound_edge_pixels = 0;      // e_B (0 without a bound)
  double base_edge_pixels = 0;       // T0's projected edge length, pixels (as e_B)
  double finest_edge_pixels = 0;     // base_edge_pixels / 2^levels
};

// The median over `cameras` of each camera's median projected edge of (V, F) (pixels, the
// edges with both ends in front of the camera and in its image); 0 when no camera sees one.
double MedianProjectedEdge(const std::vector<vision::Camera>& cameras, const geometry::Positions& V,
                           const geometry::Faces& F);

// floor(log2(edge_pixels / target_pixels)) clamped to [0, max_levels].
int LevelsForEdge(double edge_pixels, double target_pixels, int max_levels);

// T0 and the levels for the reference hull `hull` (steps 1–4 above); `voxel_size` in world
// units, `source` names the hull in errors. Throws subflow::Error as geometry::SimplifyMesh.
BaseResolution ChooseBaseResolution(const geometry::TriangleMesh& hull, const std::vector<vision::Camera>& cameras,
                                    double voxel_size, const ShapeInitOptions& options, const std::string& source);

}  // namespace subflow::solver
