// ExtractIsosurface: CGAL Mesh_3 on a gray-level image domain, surface criteria only.
// Kept alone in this file because Mesh_3 is the heaviest CGAL package to compile.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_3/Mesher_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_facet_topology.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Random.h>
#include <CGAL/facets_in_complex_3_to_triangle_mesh.h>
#include <Eigen/Geometry>

#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/isosurface.h"
#include "geometry/mesh_topology.h"

namespace subflow::geometry {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using MeshDomain = CGAL::Labeled_mesh_domain_3<Kernel>;
using Triangulation =
    CGAL::Mesh_triangulation_3<MeshDomain, CGAL::Default, CGAL::Sequential_tag>::type;
using Complex = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;
using Point = Kernel::Point_3;
namespace params = CGAL::parameters;

// Surface points are found by bisection on segments down to this length (voxels).
constexpr double kIntersectionToleranceVoxels = 1e-3;

// Mesh_3 draws from CGAL's default random generator; fix it for the duration of one
// extraction and give the caller's generator back afterwards.
class ScopedDefaultRandom {
 public:
  explicit ScopedDefaultRandom(unsigned int seed) : saved_(CGAL::get_default_random()) {
    CGAL::get_default_random() = CGAL::Random(seed);
  }
  ~ScopedDefaultRandom() { CGAL::get_default_random() = saved_; }

 private:
  CGAL::Random saved_;
};

// A float CGAL::Image_3 holding the samples of `field` in voxel units: sample (i, j, k)
// at (i, j, k) (same x-fastest layout as ScalarVolume). Meshing in voxel units keeps
// float image offsets and Mesh_3's absolute margins (one unit around the image) out of
// the world's scale; ExtractIsosurface maps the result back.
CGAL::Image_3 MakeVoxelImage(const ScalarVolume& field) {
  _image* image = ::_createImage(field.nx, field.ny, field.nz, 1, 1.0, 1.0, 1.0, sizeof(float),
                                 WK_FLOAT, SGN_SIGNED);
  SUBFLOW_CHECK(image != nullptr, "allocating the CGAL image failed");
  std::memcpy(image->data, field.values.data(), field.values.size() * sizeof(float));
  return CGAL::Image_3(image);
}

// Inserts the surface point of every seed segment into the triangulation, as Mesh_3's
// own image initialization does, so that every component of the inside gets refined.
void InsertSeeds(const std::vector<IsosurfaceSeed>& seeds, const MeshDomain& domain,
                 Complex* c3t3) {
  Triangulation& tr = c3t3->triangulation();
  const auto construct_intersection = domain.construct_intersection_object();
  const auto weighted = tr.geom_traits().construct_weighted_point_3_object();
  for (const IsosurfaceSeed& seed : seeds) {  // in voxel units, see MakeVoxelImage
    const Kernel::Segment_3 segment(Point(seed.inside.x(), seed.inside.y(), seed.inside.z()),
                                    Point(seed.outside.x(), seed.outside.y(), seed.outside.z()));
    const MeshDomain::Intersection intersection = construct_intersection(segment);
    if (std::get<2>(intersection) == 0) continue;  // no crossing found (cannot happen)
    const Triangulation::Vertex_handle v = tr.insert(weighted(std::get<0>(intersection)));
    if (v == Triangulation::Vertex_handle()) continue;  // hidden point
    c3t3->set_dimension(v, 2);
    c3t3->set_index(v, std::get<1>(intersection));
  }
  if (tr.dimension() == 3) return;
  // Seeds all coplanar (a flat object): add the domain's own random surface points.
  std::vector<std::pair<Point, MeshDomain::Index>> points;
  domain.construct_initial_points_object()(std::back_inserter(points), 20);
  for (const auto& [point, index] : points) {
    const Triangulation::Vertex_handle v = tr.insert(weighted(point));
    if (v == Triangulation::Vertex_handle()) continue;
    c3t3->set_dimension(v, 2);
    c3t3->set_index(v, index);
  }
}

// The boundary facets of the complex as a closed, outward-oriented 2-manifold.
// Mesh_3 labels every cell by the subdomain of its circumcentre, and a facet is in the
// complex exactly when the circumcentres of its two cells (the ends of its dual Voronoi
// edge) carry different labels; the soup orients each facet from the cell labelled 1
// (inside) towards the one labelled 0, i.e. outwards, cavities included. Shared points are
// merged by the soup, so MeshTopology can then verify manifoldness and orientation.
TriangleMesh ExtractBoundary(const Complex& c3t3, const std::string& source) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> triangles;
  CGAL::Mesh_3::internal::facets_in_complex_3_to_triangle_soup(c3t3, points, triangles);
  if (triangles.empty())
    ThrowError(source, "surface", "Mesh_3 produced no surface triangle");
  TriangleMesh mesh;
  mesh.V.resize(static_cast<int>(points.size()), 3);
  for (size_t v = 0; v < points.size(); ++v)
    mesh.V.row(static_cast<int>(v)) << points[v].x(), points[v].y(), points[v].z();
  mesh.F.resize(static_cast<int>(triangles.size()), 3);
  for (size_t f = 0; f < triangles.size(); ++f)
    mesh.F.row(static_cast<int>(f)) << triangles[f][0], triangles[f][1], triangles[f][2];
  return mesh;
}

}  // namespace

TriangleMesh ExtractIsosurface(const ScalarVolume& volume, const IsosurfaceOptions& options,
                               IsosurfaceSummary* summary, const std::string& source) {
  options.Check();
  CheckScalarVolume(volume, source);
  const double iso = options.iso_value;
  if (std::all_of(volume.values.begin(), volume.values.end(), [&](float x) { return x > iso; }))
    ThrowError(source, "values",
               "every voxel is occupied (value > iso_value " + std::to_string(iso) +
                   "): the volume does not enclose the object");

  IsosurfaceSummary stats;
  Stopwatch start;
  const double sigma = options.smoothing_sigma_voxels;
  const int blur_reach = sigma > 0.0 ? static_cast<int>(std::ceil(3.0 * sigma)) + 1 : 1;
  ScalarVolume field =
      PadAndSmoothVolume(volume, std::max(options.padding_voxels, blur_reach), sigma);
  // Mesh in voxel units (see MakeVoxelImage); world = world_origin + spacing · voxel.
  const Eigen::Vector3d world_origin = field.origin;
  field.origin.setZero();
  field.spacing = 1.0;
  int outside_component_count = 0;
  const std::vector<IsosurfaceSeed> seeds =
      FindIsosurfaceSeeds(field, iso, &stats.component_count, &outside_component_count);
  // The padding makes the grid border one outside component; the others are cavities.
  stats.cavity_count = std::max(0, outside_component_count - 1);
  if (stats.component_count == 0)
    ThrowError(source, "values",
               "no voxel is occupied (no value > iso_value " + std::to_string(iso) +
                   " after smoothing with σ = " + std::to_string(sigma) +
                   " voxels): the volume is empty or its objects are thinner than the blur");
  stats.prepare_seconds = start.Seconds();

  start.Restart();
  const ScopedDefaultRandom scoped_random(options.random_seed);
  CGAL::Random domain_random(options.random_seed);
  const CGAL::Image_3 image = MakeVoxelImage(field);
  // Mesh_3 measures the bisection tolerance relative to the diagonal of the image's
  // bounding box, which it enlarges by one unit (here a voxel) on every side.
  const double diagonal = Eigen::Vector3d(field.nx + 2.0, field.ny + 2.0, field.nz + 2.0).norm();
  const MeshDomain domain = MeshDomain::create_gray_image_mesh_domain(
      image, params::iso_value = static_cast<float>(iso), params::value_outside = 0.0f,
      params::relative_error_bound = kIntersectionToleranceVoxels / diagonal,
      params::p_rng = &domain_random);
  const Criteria criteria(params::facet_angle = options.facet_angle_degrees,
                          params::facet_size = options.facet_size_voxels,
                          params::facet_distance = options.facet_distance_voxels);
  Complex c3t3;
  InsertSeeds(seeds, domain, &c3t3);
  // The engine of CGAL::refine_mesh_3 without its optimizers (ODT, Lloyd, perturbation,
  // exudation act on cells, which we do not need): instantiating them cost this file 30 %
  // more compile time and 80 % more memory. MANIFOLD is refine_mesh_3's manifold().
  CGAL::Mesh_3::Mesher_3<Complex, Criteria, MeshDomain> mesher(
      c3t3, domain, criteria, CGAL::MANIFOLD, static_cast<std::size_t>(options.max_vertex_count));
  mesher.refine_mesh();
  stats.mesh_seconds = start.Seconds();

  start.Restart();
  TriangleMesh mesh = ExtractBoundary(c3t3, source);
  mesh.V = ((volume.spacing * mesh.V).rowwise() + world_origin.transpose()).eval();
  // What matters downstream: a closed, consistently oriented 2-manifold (MeshTopology throws
  // on a non-manifold edge or vertex and on flipped neighbours) bounding a positive volume.
  const MeshTopology topology(mesh.F, mesh.vertex_count(), source + " (iso-surface)");
  if (!topology.IsClosed())
    ThrowError(source, "surface",
               "the extracted surface has " + std::to_string(topology.BoundaryEdgeCount()) +
                   " boundary edges; try a smaller facet_size_voxels or a larger "
                   "max_vertex_count");
  double signed_volume = 0.0;
  for (int f = 0; f < mesh.face_count(); ++f)
    signed_volume += mesh.V.row(mesh.F(f, 0)).dot(
        mesh.V.row(mesh.F(f, 1)).cross(mesh.V.row(mesh.F(f, 2))));
  SUBFLOW_CHECK(signed_volume > 0.0, "Mesh_3 facets must be oriented outwards");
  stats.vertex_count = mesh.vertex_count();
  stats.face_count = mesh.face_count();
  stats.extract_seconds = start.Seconds();
  if (summary != nullptr) *summary = stats;
  return mesh;
}

}  // namespace subflow::geometry
