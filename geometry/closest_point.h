// Queries against a fixed triangle mesh: closest surface point, ray casting and
// inside/outside. Closest points and inside/outside are answered by a CGAL AABB tree (kept
// inside closest_point_cgal.cpp); rays by Embree (geometry/ray_caster.h), with CGAL's
// exact-predicate traversal kept as the reference they are tested and benchmarked against
// (RayEngine::kCgal).
//
// Conventions
//   A surface point is (face f, barycentric (u, v)):
//     point = (1 − u − v)·V[F(f,0)] + u·V[F(f,1)] + v·V[F(f,2)],   u, v ≥ 0, u + v ≤ 1.
//   Faces whose three corners are collinear (zero area) are left out of the tree: no
//   query ever returns them. Distances are Euclidean, in the mesh's units.
//   Rays: origin + t·direction with `direction` normalized internally, so t is a
//   distance; a ray hit has t ≥ 0, a line hit has t of either sign.
//
// Thread safety: the tree is built in the constructor; every const member may be called
// concurrently. Batch queries run in parallel (TBB).
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int face = -1;                                         // row of F; −1 = none
  Eigen::Vector2d barycentric = Eigen::Vector2d::Zero();  // (u, v), see above
  double distance = std::numeric_limits<double>::infinity();  // query → point
};

struct RayHit {
  bool hit = false;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  int face = -1;
  Eigen::Vector2d barycentric = Eigen::Vector2d::Zero();
  // Signed distance along the (normalized) direction: point = origin + t·direction.
  double t = std::numeric_limits<double>::infinity();
};

enum class PointSide { kInside, kOnSurface, kOutside };

// Who answers ray queries: Embree (float BVH, hit parameter refined in double; the
// default), or CGAL's AABB tree with exact predicates (the reference).
enum class RayEngine { kEmbree, kCgal };

class ClosestPointTree {
 public:
  // Copies V and F and builds the tree. Throws subflow::Error (naming `source`) when F
  // indexes a vertex out of range, V is not finite, or no face has a non-zero area.
  explicit ClosestPointTree(const TriangleMesh& mesh, const std::string& source = "mesh");
  ~ClosestPointTree();
  ClosestPointTree(ClosestPointTree&&) noexcept;
  ClosestPointTree& operator=(ClosestPointTree&&) noexcept;
  ClosestPointTree(const ClosestPointTree&) = delete;
  ClosestPointTree& operator=(const ClosestPointTree&) = delete;

  const TriangleMesh& mesh() const;

  // The point of the surface nearest to `query`.
  SurfacePoint Closest(const Eigen::Vector3d& query) const;
  // Closest() of every row of `queries` (#Q×3), in parallel.
  std::vector<SurfacePoint> ClosestPoints(const Positions& queries) const;
  // Distances only (cheaper to return), in parallel: #Q values.
  Eigen::VectorXd Distances(const Positions& queries) const;

  // First surface point along the ray origin + t·direction, t ∈ [0, max_t]. `hit` is
  // false when there is none (or `direction` is zero).
  RayHit FirstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                  double max_t = std::numeric_limits<double>::infinity(),
                  RayEngine engine = RayEngine::kEmbree) const;
  // The surface point on the whole line origin + t·direction nearest to the origin
  // (smallest |t|, either direction), |t| ≤ max_abs_t. For snapping a point to a
  // surface along its normal.
  RayHit NearestHitOnLine(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                          double max_abs_t = std::numeric_limits<double>::infinity(),
                          RayEngine engine = RayEngine::kEmbree) const;
  // NearestHitOnLine over rows of `origins` and `directions` (#Q×3 each), in parallel.
  std::vector<RayHit> NearestHitsOnLines(
      const Positions& origins, const Positions& directions,
      double max_abs_t = std::numeric_limits<double>::infinity(),
      RayEngine engine = RayEngine::kEmbree) const;

  // Inside / outside of the volume bounded by the mesh: the ray-parity test of
  // CGAL::Side_of_triangle_mesh (crossings of a ray from the point, re-cast when a ray
  // grazes an edge or vertex), run on this tree. Meaningful only for a closed,
  // non-self-intersecting mesh; the caller is responsible for that.
  PointSide Side(const Eigen::Vector3d& point) const;
  bool IsInside(const Eigen::Vector3d& point) const { return Side(point) == PointSide::kInside; }
  // Distance to the surface, negative inside (closed meshes only, as Side).
  double SignedDistance(const Eigen::Vector3d& point) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Barycentric (u, v) of `point` with respect to face f of `mesh` (least squares in the
// plane of the face; exact when the point lies on it). Degenerate faces give (0, 0).
Eigen::Vector2d FaceBarycentric(const TriangleMesh& mesh, int face, const Eigen::Vector3d& point);
// The point of face f at barycentric (u, v).
Eigen::Vector3d FacePoint(const Positions& V, const Faces& F, int face, const Eigen::Vector2d& uv);

}  // namespace subflow::geometry
