// Samples of the limit surface for the normal-flow constraints (method §4.2) and the
// stereo functional (§4.3): a regular pattern inside every face (patch) of one level,
// about one sample per pixel of the finest image that sees the patch. Each sample is a
// limit point s = L c (eq. 12) with its face and barycentric parameters kept, so the
// derivatives ∂s/∂c are the rows of L (eq. 13) and flow back to control points and,
// through the refinement and frames, to base control and detail vectors (eq. 24).
//
// Pattern inside a face of density m (FaceSamplePattern): the centroids of the m² small
// triangles of the face's regular 1-to-m² split — (u, v) = ((i + 1/3)/m, (j + 1/3)/m) for
// i + j ≤ m − 1 ("up" triangles) and ((i + 2/3)/m, (j + 2/3)/m) for i + j ≤ m − 2
// ("down" triangles). Every sample lies strictly inside its face (no sample is shared by
// two faces) and each represents area/m² of the patch.
//
// Density: m = clamp(⌈√(samples_per_pixel · A)⌉, 1, max_density), where A is the largest
// projected area (pixels², undistorted pinhole) of the face over the cameras it faces
// (its limit-position corners in front of the camera, its normal towards the centre,
// at least one corner inside the image). A face no camera faces gets m = 1.
#pragma once

#include <vector>

#include "geometry/limit_evaluation.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::solver {

struct SurfaceSamplingOptions {
  double samples_per_pixel = 1.0;  // target samples per pixel² of the finest view of a patch
  int max_density = 12;            // at most max_density² samples per face

  void Check() const;  // throws subflow::Error naming the field
};

struct SurfaceSamples {
  int level = 0;                               // the level whose faces are sampled
  std::vector<geometry::FaceSample> samples;   // face, (u, v) per sample
  std::vector<int> face_density;               // m per face of `level`
  std::vector<int> face_first_sample;          // #F + 1 offsets: samples of face f are
                                               // [face_first_sample[f], face_first_sample[f+1])
  geometry::SparseMatrix limit;                // L: #S × #V(level), s = L c
  geometry::SparseMatrix limit_du, limit_dv;   // ∂s/∂u = L_u c, ∂s/∂v = L_v c

  int size() const { return static_cast<int>(samples.size()); }
  // Sample positions L c (#S×3) and unit normals (L_u c × L_v c, normalized; #S×3).
  geometry::Positions SamplePositions(const geometry::Positions& control) const;
  geometry::Positions SampleNormals(const geometry::Positions& control) const;
};

// The m² barycentric points of one face (see the file comment), appended to `samples`.
void AppendFaceSamplePattern(int face, int density, std::vector<geometry::FaceSample>* samples);

// Per-face densities of `level` for control points `control` (#V(level)×3) seen by
// `cameras` (see the file comment).
std::vector<int> FaceSampleDensities(const geometry::LoopHierarchy& hierarchy, int level,
                                     const geometry::Positions& control,
                                     const std::vector<vision::Camera>& cameras,
                                     const SurfaceSamplingOptions& options);

// Samples every face of `level` with its density and evaluates L, L_u, L_v exactly
// (LoopLimitEvaluator on the level's topology). Throws subflow::Error when `control`
// does not have #V(level) rows or the level is out of range.
SurfaceSamples SampleLimitSurface(const geometry::LoopHierarchy& hierarchy, int level,
                                  const geometry::Positions& control,
                                  const std::vector<vision::Camera>& cameras,
                                  const SurfaceSamplingOptions& options);

}  // namespace subflow::solver
