// DistanceBound: the two-sided distance rule of bounded simplification (see the header).
#include "geometry/simplify_bound_cgal.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <CGAL/boost/graph/Euler_operations.h>

namespace subflow::geometry::simplify_internal {
namespace {

Point Centroid(const Point& a, const Point& b, const Point& c) {
  return Point((a.x() + b.x() + c.x()) / 3.0, (a.y() + b.y() + c.y()) / 3.0, (a.z() + b.z() + c.z()) / 3.0);
}

// The faces around v0 and v1 (each once).
std::vector<FaceIndex> FacesAround(const SurfaceMesh& mesh, VertexIndex v0, VertexIndex v1) {
  std::vector<FaceIndex> faces;
  for (const VertexIndex v : {v0, v1})
    for (const FaceIndex f : CGAL::faces_around_target(mesh.halfedge(v), mesh))
      if (f != SurfaceMesh::null_face() && std::find(faces.begin(), faces.end(), f) == faces.end())
        faces.push_back(f);
  return faces;
}

}  // namespace

DistanceBound::DistanceBound(const TriangleMesh& input, SurfaceMesh* mesh, double max_distance)
    : mesh_(mesh), max_distance_(max_distance),
      input_tree_(std::make_unique<ClosestPointTree>(input, "simplification input")) {
  attributed_ = mesh_->add_property_map<FaceIndex, std::vector<int>>("f:bound_samples").first;
  for (const FaceIndex f : mesh_->faces()) {
    const HalfedgeIndex h = mesh_->halfedge(f);
    const Point& a = mesh_->point(mesh_->source(h));
    const Point& b = mesh_->point(mesh_->target(h));
    const Point& c = mesh_->point(mesh_->target(mesh_->next(h)));
    attributed_[f].push_back(static_cast<int>(samples_.size()));
    samples_.push_back(Centroid(a, b, c));
  }
  for (const VertexIndex v : mesh_->vertices()) {
    const FaceIndex f = mesh_->face(mesh_->halfedge(v));
    if (f == SurfaceMesh::null_face()) continue;
    attributed_[f].push_back(static_cast<int>(samples_.size()));
    samples_.push_back(mesh_->point(v));
  }
}

double DistanceBound::DistanceToInput(const Point& p) const {
  return input_tree_->Closest(Eigen::Vector3d(p.x(), p.y(), p.z())).distance;
}

double DistanceBound::Distance(const Point& p, const Triangle& t) {
  // The closest point of the triangle by its Voronoi regions (Ericson, Real-Time Collision
  // Detection, 5.1.5); a degenerate triangle falls to an edge or corner region.
  const Kernel::Vector_3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
  const double d1 = ab * ap, d2 = ac * ap;
  if (d1 <= 0 && d2 <= 0) return std::sqrt(ap.squared_length());
  const Kernel::Vector_3 bp = p - t.b;
  const double d3 = ab * bp, d4 = ac * bp;
  if (d3 >= 0 && d4 <= d3) return std::sqrt(bp.squared_length());
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return std::sqrt((ap - (d1 / (d1 - d3)) * ab).squared_length());
  const Kernel::Vector_3 cp = p - t.c;
  const double d5 = ab * cp, d6 = ac * cp;
  if (d6 >= 0 && d5 <= d6) return std::sqrt(cp.squared_length());
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return std::sqrt((ap - (d2 / (d2 - d6)) * ac).squared_length());
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return std::sqrt((bp - ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (t.c - t.b)).squared_length());
  const double sum = va + vb + vc;
  if (!(sum > 0)) return std::sqrt(ap.squared_length());  // zero area: a corner is as good
  const double v = vb / sum, w = vc / sum;
  return std::sqrt((ap - v * ab - w * ac).squared_length());
}

double DistanceBound::Nearest(const Point& p, const std::vector<Triangle>& triangles, std::size_t* nearest) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const double d = Distance(p, triangles[t]);
    if (d < best) best = d, *nearest = t;
  }
  return best;
}

bool DistanceBound::Keeps(const std::vector<FaceIndex>& faces, const std::vector<int>& successor,
                          const std::vector<Triangle>& triangles) const {
  if (triangles.empty()) return false;
  std::size_t nearest = 0;
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (const int s : attributed_[faces[i]]) {
      // Most samples stay close to what their own face becomes: test that first.
      if (successor[i] >= 0 && Distance(samples_[s], triangles[successor[i]]) <= max_distance_) continue;
      if (Nearest(samples_[s], triangles, &nearest) > max_distance_) return false;
    }
  for (const Triangle& t : triangles)
    if (DistanceToInput(Centroid(t.a, t.b, t.c)) > max_distance_) return false;
  return true;
}

bool DistanceBound::AllowsCollapse(VertexIndex v0, VertexIndex v1, const Point& p) const {
  if (DistanceToInput(p) > max_distance_) return false;
  const std::vector<FaceIndex> faces = FacesAround(*mesh_, v0, v1);
  std::vector<Triangle> triangles;
  std::vector<int> successor;  // per face: its triangle after the collapse, −1 if it vanishes
  for (const FaceIndex f : faces) {
    Point corners[3];
    int moved = 0, k = 0;
    for (const VertexIndex v : CGAL::vertices_around_face(mesh_->halfedge(f), *mesh_)) {
      const bool merged = v == v0 || v == v1;
      moved += merged;
      corners[k++] = merged ? p : mesh_->point(v);
    }
    successor.push_back(moved == 1 ? static_cast<int>(triangles.size()) : -1);  // the edge's faces vanish
    if (moved == 1) triangles.push_back({corners[0], corners[1], corners[2]});
  }
  return Keeps(faces, successor, triangles);
}

void DistanceBound::BeforeCollapse(VertexIndex v0, VertexIndex v1) {
  pending_.clear();
  for (const FaceIndex f : FacesAround(*mesh_, v0, v1)) {
    pending_.insert(pending_.end(), attributed_[f].begin(), attributed_[f].end());
    attributed_[f].clear();
  }
}

void DistanceBound::Attribute(const std::vector<int>& samples, const std::vector<FaceIndex>& faces) {
  std::vector<Triangle> triangles;
  for (const FaceIndex f : faces) {
    const HalfedgeIndex h = mesh_->halfedge(f);
    triangles.push_back({mesh_->point(mesh_->source(h)), mesh_->point(mesh_->target(h)),
                         mesh_->point(mesh_->target(mesh_->next(h)))});
  }
  for (const int s : samples) {
    std::size_t nearest = 0;
    Nearest(samples_[s], triangles, &nearest);
    attributed_[faces[nearest]].push_back(s);
  }
}

void DistanceBound::AfterCollapse(VertexIndex kept) {
  Attribute(pending_, FacesAround(*mesh_, kept, kept));
  pending_.clear();
}

bool DistanceBound::AllowsFlip(HalfedgeIndex h) const {
  const HalfedgeIndex g = mesh_->opposite(h);
  const Point& a = mesh_->point(mesh_->source(h));
  const Point& b = mesh_->point(mesh_->target(h));
  const Point& c = mesh_->point(mesh_->target(mesh_->next(h)));
  const Point& d = mesh_->point(mesh_->target(mesh_->next(g)));
  return Keeps({mesh_->face(h), mesh_->face(g)}, {-1, -1}, {{a, d, c}, {d, b, c}});
}

void DistanceBound::Flip(HalfedgeIndex h) {
  const std::vector<FaceIndex> faces = {mesh_->face(h), mesh_->face(mesh_->opposite(h))};
  std::vector<int> samples;
  for (const FaceIndex f : faces) {
    samples.insert(samples.end(), attributed_[f].begin(), attributed_[f].end());
    attributed_[f].clear();
  }
  CGAL::Euler::flip_edge(h, *mesh_);  // keeps the two face indices
  Attribute(samples, faces);
}

double DistanceBound::LargestSampleDistance(const ClosestPointTree& result) const {
  Positions points(static_cast<Eigen::Index>(samples_.size()), 3);
  for (std::size_t s = 0; s < samples_.size(); ++s)
    points.row(static_cast<Eigen::Index>(s)) << samples_[s].x(), samples_[s].y(), samples_[s].z();
  return samples_.empty() ? 0.0 : result.Distances(points).maxCoeff();
}

}  // namespace subflow::geometry::simplify_internal
