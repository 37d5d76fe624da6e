// SimplifyMesh: CGAL edge collapse with Garland–Heckbert quadrics, shape and valence
// filters, a valence-improving flip pass and a self-intersection guard.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh_simplification/Edge_collapse_visitor_base.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <boost/optional.hpp>

#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/closest_point.h"
#include "geometry/mesh_topology.h"
#include "geometry/simplify.h"
#include "geometry/simplify_bound_cgal.h"

namespace subflow::geometry {
namespace {

using simplify_internal::DistanceBound;
using simplify_internal::HalfedgeIndex;
using simplify_internal::Kernel;
using simplify_internal::Point;
using simplify_internal::SurfaceMesh;
using simplify_internal::VertexIndex;
using Vector = Kernel::Vector_3;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;
using GarlandHeckbert = SMS::GarlandHeckbert_plane_policies<SurfaceMesh, Kernel>;

constexpr double kDegree = 3.14159265358979323846 / 180.0;

double AngleBetween(const Vector& a, const Vector& b) {
  return std::atan2(std::sqrt(CGAL::cross_product(a, b).squared_length()), a * b);
}

Vector Normal(const Point& a, const Point& b, const Point& c) {
  return CGAL::cross_product(b - a, c - a);
}

// Smallest interior angle of triangle (a, b, c), radians (0 for a degenerate one).
double SmallestAngle(const Point& a, const Point& b, const Point& c) {
  return std::min({AngleBetween(b - a, c - a), AngleBetween(a - b, c - b),
                   AngleBetween(a - c, b - c)});
}

// Stops the collapse once the mesh has at most `target` faces.
struct FaceCountStop {
  const SurfaceMesh* mesh;
  std::size_t target;
  template <typename Cost, typename Profile>
  bool operator()(const Cost&, const Profile&, std::size_t, std::size_t) const {
    return mesh->number_of_faces() <= target;
  }
};

// Refuses collapses that bend, degrade or over-connect the mesh (see simplify.h), and, with
// a distance bound, those that break it.
class ShapeAndValenceFilter {
 public:
  ShapeAndValenceFilter(const SimplifyOptions& options, const DistanceBound* bound)
      : bound_(bound),
        max_normal_change_(options.max_normal_change_degrees * kDegree),
        min_angle_(options.min_triangle_angle_degrees * kDegree),
        max_valence_(options.max_valence),
        min_valence_(options.min_valence) {}

  template <typename Profile>
  boost::optional<typename Profile::Point> operator()(
      const Profile& profile, boost::optional<typename Profile::Point> placement) const {
    if (!placement) return placement;
    const SurfaceMesh& mesh = profile.surface_mesh();
    // On a closed surface the merged vertex is adjacent to the whole link of the edge.
    if (static_cast<int>(profile.link().size()) > max_valence_) return boost::none;
    for (const VertexIndex opposite : {profile.vL(), profile.vR()}) {
      if (opposite != SurfaceMesh::null_vertex() &&
          static_cast<int>(mesh.degree(opposite)) - 1 < min_valence_)
        return boost::none;
    }
    const Point& p = *placement;
    const auto& triangles = profile.triangles();
    // The first triangles are the one or two faces of the edge, which disappear.
    const std::size_t first = (profile.left_face_exists() ? 1 : 0) +
                              (profile.right_face_exists() ? 1 : 0);
    for (std::size_t t = first; t < triangles.size(); ++t) {
      // triangles[t].v1 is the end of the edge that moves to p.
      const Point& a = mesh.point(triangles[t].v0);
      const Point& b = mesh.point(triangles[t].v1);
      const Point& c = mesh.point(triangles[t].v2);
      if (AngleBetween(Normal(a, b, c), Normal(a, p, c)) > max_normal_change_)
        return boost::none;
      const double new_angle = SmallestAngle(a, p, c);
      if (new_angle < min_angle_ && new_angle < SmallestAngle(a, b, c)) return boost::none;
    }
    if (bound_ != nullptr && !bound_->AllowsCollapse(profile.v0(), profile.v1(), p)) return boost::none;
    return placement;
  }

 private:
  const DistanceBound* bound_;
  double max_normal_change_, min_angle_;
  int max_valence_, min_valence_;
};

// Hands the samples of a collapsing star to the new star (DistanceBound).
struct BoundVisitor : SMS::Edge_collapse_visitor_base<SurfaceMesh> {
  DistanceBound* bound;
  explicit BoundVisitor(DistanceBound* b) : bound(b) {}
  template <typename Profile, typename Placement>
  void OnCollapsing(const Profile& profile, const Placement&) {
    if (bound != nullptr) bound->BeforeCollapse(profile.v0(), profile.v1());
  }
  template <typename Profile>
  void OnCollapsed(const Profile&, VertexIndex kept) {
    if (bound != nullptr) bound->AfterCollapse(kept);
  }
};

// Garland–Heckbert collapses, cheapest first, down to `target` faces (or until no collapse
// passes the filters and the bound).
void Collapse(std::size_t target, const SimplifyOptions& options, DistanceBound* bound, SurfaceMesh* mesh) {
  GarlandHeckbert garland_heckbert(*mesh);
  SMS::edge_collapse(*mesh, FaceCountStop{mesh, target},
                     CGAL::parameters::get_cost(garland_heckbert.get_cost())
                         .get_placement(garland_heckbert.get_placement())
                         .filter(ShapeAndValenceFilter(options, bound))
                         .visitor(BoundVisitor(bound)));
}

SurfaceMesh ToSurfaceMesh(const TriangleMesh& mesh) {
  SurfaceMesh result;
  std::vector<VertexIndex> vertex_of(mesh.vertex_count(), SurfaceMesh::null_vertex());
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.F(f, k);
      if (vertex_of[v] == SurfaceMesh::null_vertex())
        vertex_of[v] = result.add_vertex(Point(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)));
    }
  for (int f = 0; f < mesh.face_count(); ++f) {
    const auto face = result.add_face(vertex_of[mesh.F(f, 0)], vertex_of[mesh.F(f, 1)],
                                      vertex_of[mesh.F(f, 2)]);
    SUBFLOW_CHECK(face != SurfaceMesh::null_face(), "a manifold mesh must convert");
  }
  return result;
}

TriangleMesh FromSurfaceMesh(SurfaceMesh mesh) {
  mesh.collect_garbage();
  TriangleMesh result;
  result.V.resize(mesh.number_of_vertices(), 3);
  for (const VertexIndex v : mesh.vertices()) {
    const Point& p = mesh.point(v);
    result.V.row(static_cast<int>(v)) << p.x(), p.y(), p.z();
  }
  result.F.resize(mesh.number_of_faces(), 3);
  int row = 0;
  for (const auto f : mesh.faces()) {
    int k = 0;
    for (const VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
      result.F(row, k++) = static_cast<int>(v);
    ++row;
  }
  return result;
}

// One greedy sweep of valence-improving flips (with a bound: those that keep it); returns
// the number of flips done.
int FlipTowardsRegularValence(const SimplifyOptions& options, DistanceBound* bound, SurfaceMesh* mesh) {
  const double max_dihedral = options.max_flip_dihedral_degrees * kDegree;
  const double min_angle = options.min_triangle_angle_degrees * kDegree;
  int flips = 0;
  for (const auto edge : mesh->edges()) {
    const HalfedgeIndex h = mesh->halfedge(edge);
    if (mesh->is_border(edge)) continue;
    const HalfedgeIndex g = mesh->opposite(h);
    // Faces (a, b, c) and (b, a, d) become (c, d, b)... i.e. (a, d, c) and (d, b, c).
    const VertexIndex a = mesh->source(h), b = mesh->target(h);
    const VertexIndex c = mesh->target(mesh->next(h)), d = mesh->target(mesh->next(g));
    if (c == d || CGAL::halfedge(c, d, *mesh).second) continue;  // flip would duplicate
    const int va = mesh->degree(a), vb = mesh->degree(b), vc = mesh->degree(c),
              vd = mesh->degree(d);
    if (va - 1 < options.min_valence || vb - 1 < options.min_valence ||
        vc + 1 > options.max_valence || vd + 1 > options.max_valence)
      continue;
    const auto deviation = [](int x) { return (x - 6) * (x - 6); };
    const int before = deviation(va) + deviation(vb) + deviation(vc) + deviation(vd);
    const int after =
        deviation(va - 1) + deviation(vb - 1) + deviation(vc + 1) + deviation(vd + 1);
    if (after >= before) continue;
    const Point &pa = mesh->point(a), &pb = mesh->point(b), &pc = mesh->point(c),
                &pd = mesh->point(d);
    const Vector n1 = Normal(pa, pd, pc), n2 = Normal(pd, pb, pc);
    const Vector old_normal = Normal(pa, pb, pc) + Normal(pb, pa, pd);
    if (AngleBetween(n1, n2) > max_dihedral || AngleBetween(n1, old_normal) > max_dihedral ||
        AngleBetween(n2, old_normal) > max_dihedral)
      continue;
    const double old_angle = std::min(SmallestAngle(pa, pb, pc), SmallestAngle(pb, pa, pd));
    const double new_angle = std::min(SmallestAngle(pa, pd, pc), SmallestAngle(pd, pb, pc));
    if (new_angle < min_angle && new_angle < old_angle) continue;
    if (bound != nullptr) {
      if (!bound->AllowsFlip(h)) continue;
      bound->Flip(h);
    } else {
      CGAL::Euler::flip_edge(h, *mesh);
    }
    ++flips;
  }
  return flips;
}

}  // namespace

TriangleMesh SimplifyMesh(const TriangleMesh& mesh, const SimplifyOptions& options,
                          SimplifySummary* summary, const std::string& source) {
  const Stopwatch start;
  options.Check();
  if (mesh.face_count() == 0) ThrowError(source, "faces", "expected at least one triangle");
  if (!mesh.V.allFinite()) ThrowError(source, "vertices", "expected finite coordinates");
  const MeshTopology topology(mesh.F, mesh.vertex_count(), source);  // throws if not manifold

  SimplifySummary stats;
  stats.input_face_count = mesh.face_count();
  const bool bounded = options.max_distance > 0.0;
  if (mesh.face_count() <= (bounded ? options.min_face_count : options.target_face_count)) {
    stats.face_count = stats.input_face_count;
    stats.vertex_count = mesh.vertex_count();
    stats.max_distance = options.max_distance;
    for (int v = 0; v < mesh.vertex_count(); ++v) ++stats.valence_histogram[topology.Valence(v)];
    stats.seconds = start.Seconds();
    if (summary != nullptr) *summary = stats;
    return mesh;
  }
  const SurfaceMesh input = ToSurfaceMesh(mesh);
  SurfaceMesh result;
  std::unique_ptr<DistanceBound> bound;
  double target = options.target_face_count, distance = options.max_distance;
  for (;;) {
    ++stats.attempts;
    bound.reset();
    result = input;
    if (bounded) {
      bound = std::make_unique<DistanceBound>(mesh, &result, distance);
      Collapse(options.min_face_count, options, bound.get(), &result);
      stats.max_distance = distance;
      stats.bound_face_count = static_cast<int>(result.number_of_faces());
      stats.bound_kept = stats.bound_face_count <= options.max_face_count;
      if (!stats.bound_kept) Collapse(options.max_face_count, options, nullptr, &result);
    } else {
      Collapse(static_cast<std::size_t>(std::lround(target)), options, nullptr, &result);
    }
    result.collect_garbage();
    stats.flips = 0;
    for (int round = 0; round < options.flip_rounds; ++round) {
      const int flips = FlipTowardsRegularValence(options, stats.bound_kept ? bound.get() : nullptr, &result);
      stats.flips += flips;
      if (flips == 0) break;
    }
    if (!options.check_self_intersections || !PMP::does_self_intersect(result)) break;
    if (stats.attempts >= options.max_attempts)
      ThrowError(source, "simplification",
                 "every attempt (" + std::to_string(stats.attempts) + ", last " +
                     (bounded ? "distance bound " + std::to_string(distance)
                              : "target " + std::to_string(std::lround(target)) + " faces") +
                     ") gave a self-intersecting mesh; raise target_face_count or lower max_distance");
    target *= options.retry_growth;
    distance /= options.retry_growth;
  }
  TriangleMesh simplified = FromSurfaceMesh(std::move(result));
  if (bound)
    stats.largest_sample_distance =
        bound->LargestSampleDistance(ClosestPointTree(simplified, source + " (simplified)"));
  bound.reset();
  const MeshTopology simplified_topology(simplified.F, simplified.vertex_count(),
                                         source + " (simplified)");
  for (int v = 0; v < simplified.vertex_count(); ++v)
    ++stats.valence_histogram[simplified_topology.Valence(v)];
  stats.face_count = simplified.face_count();
  stats.vertex_count = simplified.vertex_count();
  stats.seconds = start.Seconds();
  if (summary != nullptr) *summary = stats;
  return simplified;
}

void SimplifyOptions::Check() const {
  const auto fail = [](const char* field, const std::string& problem) {
    ThrowError("SimplifyOptions", field, problem);
  };
  if (target_face_count < 4)
    fail("target_face_count",
         "expected at least 4 faces (a tetrahedron), got " + std::to_string(target_face_count));
  if (!(max_normal_change_degrees > 0.0 && max_normal_change_degrees <= 180.0))
    fail("max_normal_change_degrees", "expected an angle in (0, 180] degrees");
  if (!(min_triangle_angle_degrees >= 0.0 && min_triangle_angle_degrees < 60.0))
    fail("min_triangle_angle_degrees", "expected an angle in [0, 60) degrees");
  if (min_valence < 3 || min_valence > 6)
    fail("min_valence", "expected 3..6, got " + std::to_string(min_valence));
  if (max_valence < 6)
    fail("max_valence", "expected at least 6, got " + std::to_string(max_valence));
  if (flip_rounds < 0) fail("flip_rounds", "expected ≥ 0");
  if (!(max_flip_dihedral_degrees > 0.0 && max_flip_dihedral_degrees < 180.0))
    fail("max_flip_dihedral_degrees", "expected an angle in (0, 180) degrees");
  if (max_attempts < 1) fail("max_attempts", "expected ≥ 1");
  if (!(max_distance >= 0.0 && std::isfinite(max_distance)))
    fail("max_distance", "expected 0 (no bound) or a finite distance > 0");
  if (min_face_count < 4) fail("min_face_count", "expected at least 4 faces (a tetrahedron)");
  if (max_face_count < min_face_count) fail("max_face_count", "expected ≥ min_face_count");
  if (!(retry_growth > 1.0 && std::isfinite(retry_growth)))
    fail("retry_growth", "expected a finite factor > 1");
}

}  // namespace subflow::geometry
