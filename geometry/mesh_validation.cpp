#include "geometry/mesh_validation.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>
#include <spdlog/fmt/fmt.h>

#include "core/error.h"
#include "geometry/mesh_topology.h"

namespace subflow::geometry {
namespace {

class UnionFind {
 public:
  explicit UnionFind(int size) : parent_(size) { std::iota(parent_.begin(), parent_.end(), 0); }
  int Find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Unite(int a, int b) { parent_[Find(a)] = Find(b); }

 private:
  std::vector<int> parent_;
};

// Combinatorics from the half-edges of the faces that do not repeat a vertex: edges,
// boundary, fins, orientation, fans around vertices (via corners united across 2-face
// edges), components and boundary loops.
void MeasureTopology(const Faces& F, int n, const std::vector<char>& face_ok,
                     MeshValidationReport* report) {
  const int m = static_cast<int>(F.rows());
  struct Halfedge {
    std::uint64_t key;  // (min vertex << 32) | max vertex
    int h;              // 3 f + k: from F(f, k) to F(f, (k + 1) % 3)
  };
  std::vector<Halfedge> halfedges;
  halfedges.reserve(3 * static_cast<size_t>(m));
  for (int f = 0; f < m; ++f) {
    if (!face_ok[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = F(f, k), b = F(f, (k + 1) % 3);
      halfedges.push_back({(std::min(a, b) << 32) | std::max(a, b), 3 * f + k});
    }
  }
  std::sort(halfedges.begin(), halfedges.end(), [](const Halfedge& x, const Halfedge& y) {
    return x.key != y.key ? x.key < y.key : x.h < y.h;
  });
  auto source = [&](int h) { return F(h / 3, h % 3); };
  auto target_corner = [](int h) { return 3 * (h / 3) + (h % 3 + 1) % 3; };

  UnionFind corners(3 * m), faces(m), boundary(n);
  std::vector<char> on_boundary(n, 0);
  for (size_t i = 0; i < halfedges.size();) {
    size_t j = i;
    while (j < halfedges.size() && halfedges[j].key == halfedges[i].key) ++j;
    ++report->edge_count;
    for (size_t k = i + 1; k < j; ++k) faces.Unite(halfedges[i].h / 3, halfedges[k].h / 3);
    const int h1 = halfedges[i].h;
    if (j - i == 1) {
      ++report->boundary_edge_count;
      const int a = source(h1), b = F(h1 / 3, (h1 % 3 + 1) % 3);
      boundary.Unite(a, b);
      on_boundary[a] = on_boundary[b] = 1;
    } else if (j - i == 2) {
      const int h2 = halfedges[i + 1].h;
      if (source(h1) == source(h2)) {
        ++report->inconsistent_edge_count;
        corners.Unite(h1, h2);
        corners.Unite(target_corner(h1), target_corner(h2));
      } else {
        corners.Unite(h1, target_corner(h2));
        corners.Unite(target_corner(h1), h2);
      }
    } else {
      ++report->non_manifold_edge_count;
    }
    i = j;
  }

  std::vector<int> fans(n, 0);
  for (int c = 0; c < 3 * m; ++c)
    if (face_ok[c / 3] && corners.Find(c) == c) ++fans[F(c / 3, c % 3)];
  int referenced = 0;
  for (int v = 0; v < n; ++v) {
    referenced += fans[v] > 0;
    report->non_manifold_vertex_count += fans[v] > 1;
    report->boundary_loop_count += on_boundary[v] && boundary.Find(v) == v;
  }
  int used_faces = 0;
  for (int f = 0; f < m; ++f)
    if (face_ok[f]) {
      ++used_faces;
      report->component_count += faces.Find(f) == f;
    }
  report->unreferenced_vertex_count = n - referenced;
  report->euler_characteristic = referenced - report->edge_count + used_faces;
  report->closed = used_faces > 0 && report->boundary_edge_count == 0;
  report->manifold = report->non_manifold_edge_count == 0 &&
                     report->non_manifold_vertex_count == 0 &&
                     report->repeated_vertex_face_count == 0;
  report->consistently_oriented = report->inconsistent_edge_count == 0;
  if (report->manifold && report->consistently_oriented)
    report->genus =
        (2 * report->component_count - report->euler_characteristic - report->boundary_loop_count) /
        2;
}

void MeasureGeometry(const TriangleMesh& mesh, const std::vector<char>& face_ok,
                     double degenerate_area_tolerance, MeshValidationReport* report) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (report->non_finite_vertex_count > 0 || mesh.vertex_count() == 0) {
    report->signed_volume = report->surface_area = nan;
    report->min_edge_length = report->mean_edge_length = report->max_edge_length = nan;
    report->bbox_min.setConstant(nan);
    report->bbox_max.setConstant(nan);
    return;
  }
  report->bbox_min = mesh.V.colwise().minCoeff().transpose();
  report->bbox_max = mesh.V.colwise().maxCoeff().transpose();
  const Eigen::RowVector3d origin = 0.5 * (report->bbox_min + report->bbox_max).transpose();

  // Each undirected edge once: the half-edge a → b with a < b, or a boundary/odd one.
  double min_length = std::numeric_limits<double>::infinity(), max_length = 0.0, sum_length = 0.0;
  long long counted = 0;
  std::vector<std::pair<std::uint64_t, double>> lengths;
  lengths.reserve(3 * static_cast<size_t>(mesh.face_count()));
  std::vector<double> areas(mesh.face_count(), 0.0);
  double volume = 0.0, area = 0.0;
  for (int f = 0; f < mesh.face_count(); ++f) {
    if (!face_ok[f]) continue;
    const Eigen::RowVector3d p0 = mesh.V.row(mesh.F(f, 0)) - origin;
    const Eigen::RowVector3d p1 = mesh.V.row(mesh.F(f, 1)) - origin;
    const Eigen::RowVector3d p2 = mesh.V.row(mesh.F(f, 2)) - origin;
    areas[f] = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    area += areas[f];
    volume += p0.dot(p1.cross(p2)) / 6.0;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      lengths.emplace_back((std::min(a, b) << 32) | std::max(a, b),
                           (mesh.V.row(mesh.F(f, k)) - mesh.V.row(mesh.F(f, (k + 1) % 3))).norm());
    }
  }
  std::sort(lengths.begin(), lengths.end());
  for (size_t i = 0; i < lengths.size(); ++i) {
    if (i > 0 && lengths[i].first == lengths[i - 1].first) continue;
    min_length = std::min(min_length, lengths[i].second);
    max_length = std::max(max_length, lengths[i].second);
    sum_length += lengths[i].second;
    ++counted;
  }
  report->signed_volume = volume;
  report->surface_area = area;
  report->min_edge_length = counted ? min_length : nan;
  report->max_edge_length = counted ? max_length : nan;
  report->mean_edge_length = counted ? sum_length / counted : nan;
  const double area_floor =
      degenerate_area_tolerance * report->mean_edge_length * report->mean_edge_length;
  for (int f = 0; f < mesh.face_count(); ++f)
    report->degenerate_face_count += face_ok[f] && areas[f] < area_floor;
  report->outward_oriented = report->closed && report->consistently_oriented && volume > 0.0;
}

void CheckSelfIntersections(const TriangleMesh& mesh, const MeshValidationOptions& options,
                            MeshValidationReport* report) {
  report->cgal.method = "CGAL";
  report->tetgen.method = "TetGen";
  const bool finite = report->non_finite_vertex_count == 0;
  if (!options.check_self_intersections_cgal)
    report->cgal.note = "skipped (option)";
  else if (!finite)
    report->cgal.note = "not run: non-finite coordinates";
  else if (!report->manifold || !report->consistently_oriented)
    report->cgal.note = "not run: CGAL's halfedge mesh needs an oriented 2-manifold";
  else
    report->cgal = FindSelfIntersectionsCgal(mesh, options.max_example_pairs);

  if (!options.check_self_intersections_tetgen)
    report->tetgen.note = "skipped (option)";
  else if (!finite)
    report->tetgen.note = "not run: non-finite coordinates";
  else
    report->tetgen = FindSelfIntersectionsTetgen(mesh);

  report->self_intersection_checks_agree =
      report->cgal.ran && report->tetgen.ran && report->cgal.found() == report->tetgen.found();
  report->self_intersecting_faces_agree =
      report->self_intersection_checks_agree &&
      report->cgal.intersecting_faces == report->tetgen.intersecting_faces &&
      report->cgal.reported_face_count == report->tetgen.reported_face_count;
}

void Judge(const MeshValidationOptions& options, MeshValidationReport* r) {
  auto& problems = r->problems;
  auto& warnings = r->warnings;
  if (r->face_count == 0) problems.push_back("the mesh has no faces");
  if (r->non_finite_vertex_count > 0)
    problems.push_back(
        fmt::format("vertices with NaN or infinite coordinates: {}", r->non_finite_vertex_count));
  if (r->repeated_vertex_face_count > 0)
    problems.push_back(fmt::format("faces repeating a vertex: {}", r->repeated_vertex_face_count));
  if (r->non_manifold_edge_count > 0)
    problems.push_back(fmt::format("non-manifold edges (bordering more than two faces): {}",
                                   r->non_manifold_edge_count));
  if (r->non_manifold_vertex_count > 0)
    problems.push_back(
        fmt::format("non-manifold vertices (their faces form several fans, e.g. a bowtie): {}",
                    r->non_manifold_vertex_count));
  if (r->inconsistent_edge_count > 0)
    problems.push_back(
        fmt::format("edges joining faces of opposite orientation: {}", r->inconsistent_edge_count));
  if (r->closed && r->manifold && r->consistently_oriented && !(r->signed_volume > 0.0))
    problems.push_back(fmt::format(
        "the closed surface is oriented inward (signed volume {:.6g} ≤ 0)", r->signed_volume));
  if (r->manifold && r->consistently_oriented && !r->topology_message.empty())
    problems.push_back("MeshTopology rejects the mesh: " + r->topology_message);
  if (r->cgal.found())
    problems.push_back(
        fmt::format("pairs of intersecting faces found by CGAL: {}{}", r->cgal.pair_count,
                    r->cgal.example_pairs.empty()
                        ? std::string()
                        : fmt::format(" (e.g. faces {} and {})", r->cgal.example_pairs[0].first,
                                      r->cgal.example_pairs[0].second)));
  if (r->tetgen.found())
    problems.push_back(
        fmt::format("self-intersecting faces found by TetGen: {}", r->tetgen.reported_face_count));

  if (!r->closed && r->face_count > 0)
    warnings.push_back(fmt::format("open surface: boundary edges {}, boundary loops {}",
                                   r->boundary_edge_count, r->boundary_loop_count));
  if (r->unreferenced_vertex_count > 0)
    warnings.push_back(fmt::format("vertices used by no face: {}", r->unreferenced_vertex_count));
  if (r->degenerate_face_count > 0)
    warnings.push_back(fmt::format("degenerate faces (area < {:g} × mean edge length²): {}",
                                   options.degenerate_area_tolerance, r->degenerate_face_count));
  for (const SelfIntersectionResult* check : {&r->cgal, &r->tetgen}) {
    const bool requested = check == &r->cgal ? options.check_self_intersections_cgal
                                             : options.check_self_intersections_tetgen;
    if (requested && !check->note.empty())
      warnings.push_back(check->method + " self-intersection test: " + check->note);
  }
  if (r->cgal.ran && r->tetgen.ran && !r->self_intersection_checks_agree)
    warnings.push_back("CGAL and TetGen disagree on whether the mesh self-intersects");
  else if (r->self_intersection_checks_agree && !r->self_intersecting_faces_agree)
    warnings.push_back(fmt::format("CGAL and TetGen find different intersecting faces ({} vs {})",
                                   r->cgal.reported_face_count, r->tetgen.reported_face_count));
}

}  // namespace

bool MeshValidationOptions::Validate(std::string* why) const {
  if (!(degenerate_area_tolerance >= 0.0)) {
    if (why) *why = "degenerate_area_tolerance must be ≥ 0";
    return false;
  }
  if (max_example_pairs < 0) {
    if (why) *why = "max_example_pairs must be ≥ 0";
    return false;
  }
  return true;
}

MeshValidationReport ValidateMesh(const TriangleMesh& mesh, const MeshValidationOptions& options,
                                  const std::string& source) {
  std::string why;
  if (!options.Validate(&why)) ThrowError(source, "validation options", why);
  if (mesh.V.cols() != 3 || mesh.F.cols() != 3)
    ThrowError(source, "mesh", "expected #V×3 positions and #F×3 faces");
  MeshValidationReport report;
  const int n = mesh.vertex_count();
  const int m = mesh.face_count();
  report.vertex_count = n;
  report.face_count = m;
  std::vector<char> face_ok(m, 1);
  for (int f = 0; f < m; ++f) {
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= n)
        ThrowError(source, "face " + std::to_string(f),
                   "vertex index " + std::to_string(mesh.F(f, k)) + " out of range [0, " +
                       std::to_string(n) + ")");
    if (mesh.F(f, 0) == mesh.F(f, 1) || mesh.F(f, 1) == mesh.F(f, 2) ||
        mesh.F(f, 0) == mesh.F(f, 2)) {
      face_ok[f] = 0;
      ++report.repeated_vertex_face_count;
    }
  }
  for (int v = 0; v < n; ++v) report.non_finite_vertex_count += !mesh.V.row(v).allFinite();

  MeasureTopology(mesh.F, n, face_ok, &report);
  try {
    MeshTopology topology(mesh.F, n, source);
  } catch (const Error& e) {
    report.topology_message = e.what();
  }
  MeasureGeometry(mesh, face_ok, options.degenerate_area_tolerance, &report);
  CheckSelfIntersections(mesh, options, &report);
  Judge(options, &report);
  return report;
}

}  // namespace subflow::geometry
