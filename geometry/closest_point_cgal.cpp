// ClosestPointTree on CGAL's AABB tree over a triangle soup (one Triangle_3 per
// non-degenerate face), so that any triangle mesh — manifold or not — can be queried.
#include "geometry/closest_point.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <type_traits>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/internal/Side_of_triangle_mesh/Point_inside_vertical_ray_cast.h>
#include <boost/heap/priority_queue.hpp>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/ray_caster.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Vector3 = Kernel::Vector_3;
using Triangle3 = Kernel::Triangle_3;
using Ray3 = Kernel::Ray_3;
using TriangleIterator = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Traits = CGAL::AABB_traits<Kernel, Primitive>;
using Tree = CGAL::AABB_tree<Traits>;
// The ray-parity test behind CGAL::Side_of_triangle_mesh, run on our tree directly:
// Side_of_triangle_mesh itself insists on a face-graph tree (it would build one for a
// soup), while this functor takes any tree of Triangle_3 primitives.
using SideOfMesh = CGAL::internal::Point_inside_vertical_ray_cast<Kernel, Tree>;

Point3 ToPoint(const Eigen::Vector3d& p) { return Point3(p.x(), p.y(), p.z()); }
Eigen::Vector3d ToEigen(const Point3& p) { return {p.x(), p.y(), p.z()}; }

template <typename Function>
void ParallelRows(Eigen::Index count, Function&& function) {
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, count, 256),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) function(i);
                    });
}

// CGAL's first_intersection of a ray (AABB_ray_intersection: boxes visited in the order of
// their entry parameter, leaves intersected, until the next box lies beyond the best hit),
// stopped at the first box entered at or beyond `cap`. Up to `cap` the same nodes are
// visited in the same order with the same arithmetic, so a hit whose parameter is below
// `cap` is exactly the one the full traversal returns; a ray that misses near its origin
// no longer walks every box to the far side of the mesh.
boost::optional<Tree::Intersection_and_primitive_id<Ray3>::Type> FirstIntersectionBefore(const Tree& tree,
                                                                                       const Ray3& ray, double cap) {
  if (tree.size() < 2 || !(cap > 0.0)) return tree.first_intersection(ray);
  const Traits& traits = tree.traits();
  if (!traits.do_intersect_object()(ray, tree.root_node()->bbox())) return boost::none;
  using Node = std::remove_const_t<std::remove_pointer_t<decltype(tree.root_node())>>;  // Tree::Node is private
  struct Entry {
    const Node* node;
    std::size_t primitives;
    double value;
    bool operator>(const Entry& other) const { return value > other.value; }
  };
  boost::heap::priority_queue<Entry, boost::heap::compare<std::greater<Entry>>> heap;
  const auto intersect = traits.intersection_object();
  const auto entry_parameter = traits.intersection_distance_object();
  // The parameter of a point of the ray along its largest direction component (CGAL's
  // as_ray_param_visitor); a segment (the ray in a triangle's plane) by its nearer end.
  const Vector3 v = ray.to_vector();
  int largest = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(v[i]) > std::abs(v[largest])) largest = i;
  struct Parameter : boost::static_visitor<double> {
    const Ray3* ray;
    Vector3 v;
    int largest;
    double operator()(const Point3& point) const { return Vector3(ray->source(), point)[largest] / v[largest]; }
    double operator()(const Kernel::Segment_3& segment) const {
      return std::min((*this)(segment[0]), (*this)(segment[1]));
    }
  } parameter;
  parameter.ray = &ray;
  parameter.v = v;
  parameter.largest = largest;

  boost::optional<Tree::Intersection_and_primitive_id<Ray3>::Type> best;
  double t = std::numeric_limits<double>::max();
  auto try_primitive = [&](const Primitive& primitive) {
    const auto hit = intersect(ray, primitive);
    if (!hit) return;
    const double distance = boost::apply_visitor(parameter, hit->first);
    if (distance < t) {
      t = distance;
      best = hit;
    }
  };
  auto push = [&](const Node& child, std::size_t primitives) {  // all of them, as CGAL (same heap order)
    if (const auto entry = entry_parameter(ray, child.bbox())) heap.push(Entry{&child, primitives, *entry});
  };
  heap.push(Entry{tree.root_node(), tree.size(), 0.0});
  while (!heap.empty() && heap.top().value < std::min(t, cap)) {
    const Entry current = heap.top();
    heap.pop();
    switch (current.primitives) {
      case 2:  // two leaves
        try_primitive(current.node->left_data());
        try_primitive(current.node->right_data());
        break;
      case 3:  // a leaf and an inner node
        try_primitive(current.node->left_data());
        push(current.node->right_child(), 2);
        break;
      default:
        push(current.node->left_child(), current.primitives / 2);
        push(current.node->right_child(), current.primitives - current.primitives / 2);
        break;
    }
  }
  return best;
}

}  // namespace

Eigen::Vector3d FacePoint(const Positions& V, const Faces& F, int face,
                          const Eigen::Vector2d& uv) {
  return (1.0 - uv.x() - uv.y()) * V.row(F(face, 0)).transpose() +
         uv.x() * V.row(F(face, 1)).transpose() + uv.y() * V.row(F(face, 2)).transpose();
}

Eigen::Vector2d FaceBarycentric(const TriangleMesh& mesh, int face, const Eigen::Vector3d& point) {
  const Eigen::Vector3d a = mesh.V.row(mesh.F(face, 0));
  const Eigen::Vector3d e1 = mesh.V.row(mesh.F(face, 1)).transpose() - a;
  const Eigen::Vector3d e2 = mesh.V.row(mesh.F(face, 2)).transpose() - a;
  const Eigen::Vector3d d = point - a;
  // Normal equations of min |u e1 + v e2 − d|.
  const double a11 = e1.dot(e1), a12 = e1.dot(e2), a22 = e2.dot(e2);
  const double b1 = e1.dot(d), b2 = e2.dot(d);
  const double det = a11 * a22 - a12 * a12;
  if (!(det > 1e-30 * a11 * a22) || det == 0.0) return Eigen::Vector2d::Zero();
  return {(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det};
}

struct ClosestPointTree::Impl {
  TriangleMesh mesh;
  std::vector<Triangle3> triangles;
  std::vector<int> face_of_triangle;  // triangles[i] is face face_of_triangle[i]
  Tree tree;
  CGAL::Bbox_3 bbox;
  std::unique_ptr<RayCaster> caster;  // the same faces as the tree; reads `mesh` (declared before it)

  int FaceOf(TriangleIterator it) const {
    return face_of_triangle[static_cast<std::size_t>(it - triangles.cbegin())];
  }

  // Hits at a ray parameter up to `max_t` (world units along the unit direction): the
  // first one, as CGAL's first_intersection finds it; beyond max_t, none or any.
  RayHit Cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& unit_direction,
              double max_t = std::numeric_limits<double>::infinity()) const {
    RayHit result;
    const Ray3 ray(ToPoint(origin), Vector3(unit_direction.x(), unit_direction.y(),
                                            unit_direction.z()));
    // The traversal's box and hit parameters and the dot product below differ by rounding
    // (~1e-15 relative): explore a little beyond max_t.
    const auto intersection = std::isfinite(max_t) ? FirstIntersectionBefore(tree, ray, max_t * (1.0 + 1e-9))
                                                   : tree.first_intersection(ray);
    if (!intersection) return result;
    Eigen::Vector3d point;
    if (const Point3* p = boost::get<Point3>(&intersection->first)) {
      point = ToEigen(*p);
    } else if (const Kernel::Segment_3* s = boost::get<Kernel::Segment_3>(&intersection->first)) {
      // The ray runs in the triangle's plane: its first point is the end nearer the origin.
      const Eigen::Vector3d p0 = ToEigen(s->source()), p1 = ToEigen(s->target());
      point = (p0 - origin).dot(unit_direction) <= (p1 - origin).dot(unit_direction) ? p0 : p1;
    } else {
      return result;
    }
    result.hit = true;
    result.point = point;
    result.face = FaceOf(intersection->second);
    result.barycentric = FaceBarycentric(mesh, result.face, point);
    result.t = std::max(0.0, (point - origin).dot(unit_direction));
    return result;
  }
  RayHit CastBy(RayEngine engine, const Eigen::Vector3d& origin, const Eigen::Vector3d& unit_direction,
                double max_t) const;
};

ClosestPointTree::ClosestPointTree(const TriangleMesh& mesh, const std::string& source)
    : impl_(std::make_unique<Impl>()) {
  Impl& impl = *impl_;
  impl.mesh = mesh;
  if (!mesh.V.allFinite()) ThrowError(source, "vertices", "expected finite coordinates");
  const int n = mesh.vertex_count();
  impl.triangles.reserve(mesh.F.rows());
  impl.face_of_triangle.reserve(mesh.F.rows());
  for (int f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= n)
        ThrowError(source, "face " + std::to_string(f),
                   "vertex index " + std::to_string(mesh.F(f, k)) + " out of range [0, " +
                       std::to_string(n) + ")");
    }
    const Triangle3 triangle(ToPoint(mesh.V.row(mesh.F(f, 0))), ToPoint(mesh.V.row(mesh.F(f, 1))),
                             ToPoint(mesh.V.row(mesh.F(f, 2))));
    if (triangle.is_degenerate()) continue;
    impl.triangles.push_back(triangle);
    impl.face_of_triangle.push_back(f);
  }
  if (impl.triangles.empty())
    ThrowError(source, "faces", "expected at least one face of non-zero area");
  impl.tree.insert(impl.triangles.cbegin(), impl.triangles.cend());
  impl.tree.build();
  // Built now, not lazily on the first (possibly concurrent) query.
  impl.tree.accelerate_distance_queries();
  impl.bbox = impl.tree.bbox();
  impl.caster = std::make_unique<RayCaster>(impl.mesh, impl.face_of_triangle);
}

ClosestPointTree::~ClosestPointTree() = default;
ClosestPointTree::ClosestPointTree(ClosestPointTree&&) noexcept = default;
ClosestPointTree& ClosestPointTree::operator=(ClosestPointTree&&) noexcept = default;

const TriangleMesh& ClosestPointTree::mesh() const { return impl_->mesh; }

SurfacePoint ClosestPointTree::Closest(const Eigen::Vector3d& query) const {
  const auto [point, id] = impl_->tree.closest_point_and_primitive(ToPoint(query));
  SurfacePoint result;
  result.point = ToEigen(point);
  result.face = impl_->FaceOf(id);
  result.barycentric = FaceBarycentric(impl_->mesh, result.face, result.point);
  result.distance = (result.point - query).norm();
  return result;
}

std::vector<SurfacePoint> ClosestPointTree::ClosestPoints(const Positions& queries) const {
  std::vector<SurfacePoint> result(static_cast<std::size_t>(queries.rows()));
  ParallelRows(queries.rows(), [&](Eigen::Index i) { result[i] = Closest(Eigen::Vector3d(queries.row(i).transpose())); });
  return result;
}

Eigen::VectorXd ClosestPointTree::Distances(const Positions& queries) const {
  Eigen::VectorXd result(queries.rows());
  ParallelRows(queries.rows(), [&](Eigen::Index i) {
    const Point3 q = ToPoint(queries.row(i).transpose());
    result[i] = std::sqrt(CGAL::to_double(impl_->tree.squared_distance(q)));
  });
  return result;
}

RayHit ClosestPointTree::Impl::CastBy(RayEngine engine, const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& unit_direction, double max_t) const {
  return engine == RayEngine::kEmbree ? caster->Cast(origin, unit_direction, max_t) : Cast(origin, unit_direction, max_t);
}

RayHit ClosestPointTree::FirstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double max_t, RayEngine engine) const {
  const double norm = direction.norm();
  if (!(norm > 0.0) || !origin.allFinite() || !direction.allFinite()) return {};
  RayHit hit = impl_->CastBy(engine, origin, direction / norm, max_t);
  if (hit.hit && hit.t > max_t) return {};
  return hit;
}

RayHit ClosestPointTree::NearestHitOnLine(const Eigen::Vector3d& origin,
                                          const Eigen::Vector3d& direction,
                                          double max_abs_t, RayEngine engine) const {
  const double norm = direction.norm();
  if (!(norm > 0.0) || !origin.allFinite() || !direction.allFinite()) return {};
  const Eigen::Vector3d unit = direction / norm;
  RayHit best = impl_->CastBy(engine, origin, unit, max_abs_t);
  if (best.hit && best.t > max_abs_t) best = {};
  if (best.hit && best.t == 0.0) return best;  // no backward hit can be nearer
  // A backward hit farther than the forward one would lose: search only that far (a short
  // segment's traversal visits few boxes of the tree).
  RayHit backward = impl_->CastBy(engine, origin, -unit, best.hit ? best.t : max_abs_t);
  if (backward.hit && backward.t <= max_abs_t && (!best.hit || backward.t < best.t)) {
    backward.t = -backward.t;
    best = backward;
  }
  return best;
}

std::vector<RayHit> ClosestPointTree::NearestHitsOnLines(const Positions& origins,
                                                         const Positions& directions,
                                                         double max_abs_t, RayEngine engine) const {
  SUBFLOW_CHECK(origins.rows() == directions.rows(), "one direction per origin");
  std::vector<RayHit> result(static_cast<std::size_t>(origins.rows()));
  ParallelRows(origins.rows(), [&](Eigen::Index i) {
    result[i] = NearestHitOnLine(Eigen::Vector3d(origins.row(i).transpose()),
                                 Eigen::Vector3d(directions.row(i).transpose()), max_abs_t, engine);
  });
  return result;
}

PointSide ClosestPointTree::Side(const Eigen::Vector3d& point) const {
  const CGAL::Bbox_3& box = impl_->bbox;
  if (point.x() < box.xmin() || point.x() > box.xmax() || point.y() < box.ymin() ||
      point.y() > box.ymax() || point.z() < box.zmin() || point.z() > box.zmax())
    return PointSide::kOutside;
  switch (SideOfMesh()(ToPoint(point), impl_->tree)) {
    case CGAL::ON_BOUNDED_SIDE: return PointSide::kInside;
    case CGAL::ON_BOUNDARY: return PointSide::kOnSurface;
    default: return PointSide::kOutside;
  }
}

double ClosestPointTree::SignedDistance(const Eigen::Vector3d& point) const {
  const double distance =
      std::sqrt(CGAL::to_double(impl_->tree.squared_distance(ToPoint(point))));
  return Side(point) == PointSide::kInside ? -distance : distance;
}

}  // namespace subflow::geometry
