// First hits of rays against a fixed triangle mesh, answered by Intel Embree (a BVH of
// single-precision triangles traversed with SIMD; Debian's libembree-dev). This is the
// fast path behind ClosestPointTree::FirstHit and NearestHitOnLine: snapping a surface to
// a hull casts two rays per vertex and pass, on every frame of shape and motion
// initialization (docs/speed.md, "Ray casts by Embree").
//
// Precision: Embree intersects in float. The mesh is stored relative to the centre of its
// bounding box (so that float's relative precision applies to the mesh's extent, not to
// its distance from the world origin), and once Embree has chosen the triangle, the hit's
// parameter is recomputed in double against that triangle's plane. A hit's t and point
// are then as precise as the CGAL reference's; only which of two triangles is hit when a
// ray passes within float rounding of their common edge can differ (Embree's robust,
// watertight mode: such a ray hits one of them, never neither).
//
// Thread safety: built in the constructor; Cast may be called concurrently.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "geometry/closest_point.h"  // RayHit
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

class RayCaster {
 public:
  // `faces` lists the rows of mesh.F to put in the scene (the others are never hit). The
  // mesh must be finite with valid indices (ClosestPointTree checks that before building
  // one), and must outlive the caster: it is read, not copied (ClosestPointTree owns both).
  RayCaster(const TriangleMesh& mesh, std::vector<int> faces);
  ~RayCaster();
  RayCaster(RayCaster&&) noexcept;
  RayCaster& operator=(RayCaster&&) noexcept;
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // The first hit of origin + t·unit_direction with t ∈ [0, max_t] (`unit_direction` of
  // length 1). A hit just beyond max_t (float rounding) may be returned: callers compare
  // t with their bound, as they do for the CGAL traversal.
  RayHit Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& unit_direction,
              double max_t = std::numeric_limits<double>::infinity()) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace subflow::geometry
