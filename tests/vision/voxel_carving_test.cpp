// Claims of vision/voxel_carving.h: from exact silhouettes of a sphere the carved
// occupancy contains the sphere and lies within the sphere's visual hull grown by about a
// voxel; a partial rig, distorted cameras and bad cameras are handled. (Morphology and
// components: voxel_morphology_test.cpp.)
#include "vision/voxel_carving.h"
#include "vision/voxel_projection.h"

#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "tests/vision/carving_test_rig.h"
#include "vision/dataset.h"

namespace subflow::vision {
namespace {

using geometry::ScalarVolume;

using namespace carving_rig;

// Distance from X to the silhouette cone of the sphere seen from camera centre C
// (0 inside the cone): |X − C| sin(β − α), β = angle of X off the axis, α = half-angle.
double DistanceToCone(const Eigen::Vector3d& X, const Eigen::Vector3d& C, const Sphere& sphere) {
  const Eigen::Vector3d axis = sphere.centre - C, v = X - C;
  const double alpha = std::asin(sphere.radius / axis.norm());
  const double beta = std::acos(std::clamp(axis.normalized().dot(v.normalized()), -1.0, 1.0));
  return beta <= alpha ? 0.0 : v.norm() * std::sin(std::min(beta - alpha, M_PI / 2));
}

std::vector<Silhouette> SphereSilhouettes(const std::vector<Camera>& cameras, const Sphere& sphere) {
  std::vector<Silhouette> silhouettes;
  for (const Camera& camera : cameras) silhouettes.push_back(SilhouetteFromMask(SphereMask(camera, sphere)));
  return silhouettes;
}

// The claims about a carved sphere: (1) conservative — every voxel whose centre lies in
// the exact visual hull (inside every camera's silhouette cone) is occupied, so in
// particular every voxel centred in the sphere, and the iso-surface at ½ encloses the
// sphere (trilinear occupancy ≥ ½ at 2000 points spread over it); (2) tight — every
// occupied voxel centre lies within `tolerance` of every cone (the visual hull grown).
// `cones` are the cameras whose cones bound the hull: everywhere, or for a camera with
// `where_seen` only at the voxels whose whole cube it projects into its image (what a
// partial view carves: voxel_carving.h, "sees").
bool CubeInImage(const Camera& camera, const Eigen::Vector3d& X, double spacing) {
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d offset((corner & 1) ? 0.5 : -0.5, (corner & 2) ? 0.5 : -0.5, (corner & 4) ? 0.5 : -0.5);
    if (!ProjectsIntoImage(camera, X + spacing * offset)) return false;
  }
  return true;
}

void ExpectHullOfSphere(const CarvingResult& result, const std::vector<Camera>& cones,
                        const Sphere& sphere, double tolerance, const std::vector<bool>& where_seen = {}) {
  const ScalarVolume& volume = result.occupancy;
  size_t in_hull = 0, in_hull_missing = 0, in_sphere = 0, outside_tolerance = 0;
  double worst_cone_distance = 0;
  for (int k = 0; k < volume.nz; ++k)
    for (int j = 0; j < volume.ny; ++j)
      for (int i = 0; i < volume.nx; ++i) {
        const Eigen::Vector3d X = volume.VoxelCenter(i, j, k);
        const bool occupied = volume.at(i, j, k) > 0.5f;
        double cone_distance = 0;
        for (std::size_t c = 0; c < cones.size(); ++c) {
          if (c < where_seen.size() && where_seen[c] && !CubeInImage(cones[c], X, volume.spacing)) continue;
          cone_distance = std::max(cone_distance, DistanceToCone(X, cones[c].Center(), sphere));
        }
        in_sphere += (X - sphere.centre).norm() <= sphere.radius;
        if (cone_distance == 0) {
          ++in_hull;
          in_hull_missing += !occupied;
        }
        if (!occupied) continue;
        worst_cone_distance = std::max(worst_cone_distance, cone_distance);
        outside_tolerance += cone_distance > tolerance;
      }
  EXPECT_GT(in_sphere, 1000u);
  EXPECT_EQ(in_hull_missing, 0u) << "of " << in_hull << " voxels centred in the visual hull were carved away";
  EXPECT_EQ(outside_tolerance, 0u) << "occupied voxels farther than " << tolerance
                                   << " from the visual hull; worst " << worst_cone_distance;
  size_t enclosed = 0;
  constexpr int kPoints = 2000;
  for (int p = 0; p < kPoints; ++p) {  // Fibonacci sphere
    const double z = 1.0 - 2.0 * (p + 0.5) / kPoints, angle = p * M_PI * (3.0 - std::sqrt(5.0));
    const Eigen::Vector3d n(std::sqrt(1 - z * z) * std::cos(angle), std::sqrt(1 - z * z) * std::sin(angle), z);
    enclosed += TrilinearOccupancy(volume, sphere.centre + sphere.radius * n) >= 0.5;
  }
  EXPECT_EQ(enclosed, static_cast<size_t>(kPoints)) << "sphere points outside the iso-surface at 1/2";
  std::printf("[ figures ] spacing %.4f, worst distance of an occupied centre to the hull %.4f (%.2f voxels)\n",
              volume.spacing, worst_cone_distance, worst_cone_distance / volume.spacing);
}

// How far outside the visual hull the conservative rule may keep a voxel centre: its
// footprint (bounding box of the projected cube, reaching √3/2 voxel from the centre)
// grown by ½ pixel must reach a silhouette pixel centre, itself within ½ pixel of the
// contour: √3/2 voxel + 1 pixel; at ≈ 2 px per voxel here that is ≈ 1.37 voxels → 1.5.
double Tolerance(const CarvingResult& result) { return 1.5 * result.occupancy.spacing; }

// The largest distance from the sphere of a point of its exact visual hull (sampled on a
// grid of step h): how much larger than the sphere a hull from these views must be.
double VisualHullExcess(const std::vector<Camera>& cameras, const Sphere& sphere, double h) {
  double excess = 0;
  const int n = static_cast<int>(std::ceil(2 * 1.5 * sphere.radius / h));
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const Eigen::Vector3d X = sphere.centre + h * Eigen::Vector3d(i, j, k) -
                                  Eigen::Vector3d::Constant(1.5 * sphere.radius);
        bool inside = true;
        for (const Camera& camera : cameras)
          inside = inside && DistanceToCone(X, camera.Center(), sphere) == 0;
        if (inside) excess = std::max(excess, (X - sphere.centre).norm() - sphere.radius);
      }
  return excess;
}

TEST(VoxelCarving, SphereFromExactMasksContainsTheSphereAndLiesWithinItsHull) {
  const Sphere sphere;
  const std::vector<Camera> cameras = SixCameras();
  const CarvingResult result = CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), kBounds, {});
  // Automatic resolution: 2 px per voxel at 333 px/m → 6 mm voxels → 0.3 m / 6 mm = 50.
  EXPECT_NEAR(result.resolution, 50, 1);
  EXPECT_EQ(result.max_misses, 0);  // masks → strict visual hull
  EXPECT_TRUE(result.warnings.empty()) << result.warnings.front();
  EXPECT_EQ(result.components_kept, 1);
  ExpectHullOfSphere(result, cameras, sphere, Tolerance(result));

  // Volume: the hull of a sphere from six views is larger than the sphere by the
  // excess computed here; the voxel count must lie between the sphere's and the grown hull's.
  const double excess = VisualHullExcess(cameras, sphere, 0.5 * result.occupancy.spacing);
  const double voxel_volume = std::pow(result.occupancy.spacing, 3);
  const double volume = result.occupied_voxels * voxel_volume;
  const double sphere_volume = 4.0 / 3.0 * M_PI * std::pow(sphere.radius, 3);
  std::printf("[ figures ] hull excess of the exact visual hull %.4f m (%.2f voxels); "
              "carved volume / sphere volume %.3f; mean silhouette IoU %.4f\n",
              excess, excess / result.occupancy.spacing, volume / sphere_volume,
              result.mean_silhouette_iou);
  EXPECT_GT(volume, sphere_volume);
  EXPECT_LT(volume, 4.0 / 3.0 * M_PI * std::pow(sphere.radius + excess + Tolerance(result), 3));
  // Reprojection: the conservative hull keeps voxel centres up to √3/2 voxel + 1 px
  // outside the cones (on average about half that) and each cube reaches ½ to √3/2 voxel
  // beyond its centre: at 2 px per voxel the projection is the silhouette grown by about
  // 3 px, hence for a silhouette of radius r px, IoU ≈ (r / (r + 3))²; required > (r / (r + 3.5))².
  for (size_t c = 0; c < cameras.size(); ++c) {
    const double distance = (cameras[c].Center() - sphere.centre).norm();
    const double r = cameras[c].K()(0, 0) * sphere.radius / std::sqrt(distance * distance - sphere.radius * sphere.radius);
    EXPECT_TRUE(result.cameras[c].used);
    EXPECT_GT(result.cameras[c].silhouette_iou, std::pow(r / (r + 3.5), 2)) << cameras[c].name() << ", r = " << r;
  }
}

// The carving rule of voxel_carving.h, evaluated literally per voxel and camera with
// Camera::Project in double precision, against CarveVoxels without cleaning (which
// projects corner planes in float and skips uniform blocks).
TEST(VoxelCarving, CarvingRuleMatchesItsDefinition) {
  const Sphere sphere;
  const std::vector<Camera> cameras = SixCameras();
  const std::vector<Silhouette> silhouettes = SphereSilhouettes(cameras, sphere);
  VoxelCarvingOptions options;
  options.resolution = 36;
  options.closing_radius = options.opening_radius = 0;
  options.min_component_fraction = 0;
  options.fill_cavities = false;
  options.compute_silhouette_iou = false;
  const CarvingResult result = CarveVoxels(cameras, silhouettes, kBounds, options);
  const ScalarVolume& grid = result.occupancy;
  size_t differences = 0, occupied = 0;
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i) {
        int hits = 0, misses = 0;
        for (size_t c = 0; c < cameras.size(); ++c) {
          const Camera& camera = cameras[c];
          Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
          bool in_front = true;
          for (int corner = 0; corner < 8; ++corner) {
            const Eigen::Vector3d X = grid.VoxelCenter(i, j, k) +
                                      grid.spacing * (Eigen::Vector3d(corner & 1, (corner >> 1) & 1, corner >> 2) -
                                                      Eigen::Vector3d::Constant(0.5));
            double depth = 0;
            const Eigen::Vector2d p = camera.Project(X, &depth);
            in_front = in_front && depth > 0;
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
          }
          if (!in_front || lo.x() < -0.5 || lo.y() < -0.5 || hi.x() >= camera.width() - 0.5 ||
              hi.y() >= camera.height() - 0.5)
            continue;  // not seen
          // Pixels whose centres lie in the footprint; per axis the nearest when none does.
          auto range = [](double a, double b, int size, int* first, int* last) {
            *first = static_cast<int>(std::ceil(a));
            *last = static_cast<int>(std::floor(b));
            if (*first > *last) *first = *last = std::clamp(static_cast<int>(std::lround(0.5 * (a + b))), 0, size - 1);
          };
          // The footprint grown by the margin, clipped to the image.
          const double m = options.footprint_margin;
          int x0, x1, y0, y1;
          range(std::max(lo.x() - m, -0.5), std::min(hi.x() + m, camera.width() - 0.5), camera.width(), &x0, &x1);
          range(std::max(lo.y() - m, -0.5), std::min(hi.y() + m, camera.height() - 0.5), camera.height(), &y0, &y1);
          double sum = 0;
          int count = 0;
          for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x, ++count) sum += silhouettes[c].evidence.at<float>(y, x);
          (sum >= options.evidence_threshold * count ? hits : misses) += 1;
        }
        const bool expected = hits >= options.min_cameras && misses == 0;
        occupied += expected;
        differences += expected != (grid.at(i, j, k) > 0.5f);
      }
  EXPECT_GT(occupied, 3000u);  // the sphere alone fills (4/3 π 0.08³) / (0.3 / 36)³ ≈ 3.7k voxels
  std::printf("[ figures ] carving vs its literal definition: %zu of %zu voxels differ\n", differences, occupied);
  // Float corner projections (error ~1e-5 px) can move a footprint edge across a pixel
  // centre only where it lies within 1e-5 px of one: a handful of voxels at most.
  EXPECT_LE(differences, 3u) << "of " << occupied << " occupied";
}

// The six cameras plus a narrow one (f = 600 px) that sees only the middle of the volume
// and only part of the sphere: voxels it does not see must be carved by the others alone.
TEST(VoxelCarving, PartialViewCarvesOnlyWhatItSees) {
  const Sphere sphere;
  std::vector<Camera> cameras = SixCameras();
  cameras.push_back(LookAt("narrow", 160, 120, 600, Spherical(0.6, 330, 30), Eigen::Vector3d::Zero()));
  VoxelCarvingOptions options;
  options.resolution = 50;  // the automatic one would follow the narrow camera (2 mm voxels)
  const CarvingResult result = CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), kBounds, options);
  EXPECT_TRUE(result.cameras.back().used);
  // The narrow camera's image is clipped by the frame: its silhouette touches the border.
  EXPECT_GT(result.cameras.back().object_pixels, 0.5 * 160 * 120);
  // Inside: the sphere's parts outside the narrow view are kept; the hull is that of the six
  // full views and, where it sees, of the narrow one (which carves what it sees of the six
  // views' hull: masks' hulls are not closed, so nothing fills that back).
  std::vector<bool> where_seen(cameras.size(), false);
  where_seen.back() = true;
  ExpectHullOfSphere(result, cameras, sphere, Tolerance(result), where_seen);
}

// Barrel distortion: the masks are in raw image coordinates, so carving must project with
// the distortion (Camera::Project). Cameras aim 6 cm beside the sphere, so its image lies
// off-centre where k1 = −0.3 moves the contour by a pixel or more.
TEST(VoxelCarving, DistortedCamerasProjectWithDistortion) {
  const Sphere sphere;
  Eigen::VectorXd distortion(5);
  distortion << -0.3, 0.05, 0.0, 0.0, 0.0;
  std::vector<Camera> cameras;
  const double directions[6][2] = {{20, 15}, {110, 15}, {200, 15}, {290, 15}, {60, 70}, {245, -50}};
  for (int c = 0; c < 6; ++c)
    cameras.push_back(LookAt("cam" + std::to_string(c), 160, 120, 200,
                             Spherical(0.6, directions[c][0], directions[c][1]),
                             Eigen::Vector3d(0.06, 0.0, -0.03), distortion));
  const CarvingResult result = CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), kBounds, {});
  ExpectHullOfSphere(result, cameras, sphere, Tolerance(result));
}

// A distorted rig's voxel corners kept from frame to frame (CornerPixelCache): the same
// occupancy as projected afresh, frame after frame, for two spheres (two frames); the
// corners are projected once per camera, and not at all for a pinhole camera or past the
// byte budget.
TEST(VoxelCarving, KeptCornersOfDistortedCamerasCarveAsProjectedOnes) {
  Eigen::VectorXd distortion(5);
  distortion << -0.3, 0.05, 0.0, 0.0, 0.0;
  std::vector<Camera> cameras;
  const double directions[6][2] = {{20, 15}, {110, 15}, {200, 15}, {290, 15}, {60, 70}, {245, -50}};
  for (int c = 0; c < 6; ++c)
    cameras.push_back(LookAt("cam" + std::to_string(c), 160, 120, 200, Spherical(0.6, directions[c][0], directions[c][1]),
                             Eigen::Vector3d(0.06, 0.0, -0.03), c == 5 ? Eigen::VectorXd() : distortion));
  Sphere moved;
  moved.centre += Eigen::Vector3d(0.03, -0.02, 0.01);
  CornerPixelCache corners;
  for (const Sphere& sphere : {Sphere(), moved}) {
    const std::vector<Silhouette> silhouettes = SphereSilhouettes(cameras, sphere);
    const CarvingResult afresh = CarveVoxels(cameras, silhouettes, kBounds, {});
    const CarvingResult kept = CarveVoxels(cameras, silhouettes, kBounds, {}, 0, &corners);
    ASSERT_EQ(kept.occupancy.size(), afresh.occupancy.size());
    EXPECT_GT(afresh.carved_voxels, 1000u);
    EXPECT_EQ(kept.carved_voxels, afresh.carved_voxels);
    EXPECT_TRUE(std::equal(kept.occupancy.values.begin(), kept.occupancy.values.end(),
                           afresh.occupancy.values.begin()));
  }
  const geometry::ScalarVolume grid = MakeVoxelGrid(kBounds, CarveVoxels(cameras, SphereSilhouettes(cameras, Sphere()),
                                                                         kBounds, {}).resolution);
  const GridCornerPixels* first = corners.Get(0, cameras[0], grid);
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(corners.Get(0, cameras[0], grid), first) << "projected again";
  EXPECT_EQ(corners.Get(5, cameras[5], grid), nullptr) << "a pinhole camera's corners are cheap";
  const VoxelCornerProjector projector(cameras[0], grid);
  for (const Eigen::Vector3i& corner : {Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(grid.nx, 3, grid.nz / 2),
                                       Eigen::Vector3i(grid.nx / 2, grid.ny / 2, grid.nz)}) {
    float u = 0, v = 0;
    projector.ProjectCorner(corner.x(), corner.y(), corner.z(), &u, &v);
    EXPECT_EQ(first->u[first->Index(corner.x(), corner.y(), corner.z())], u);
    EXPECT_EQ(first->v[first->Index(corner.x(), corner.y(), corner.z())], v);
  }
  CornerPixelCache tiny(1000);
  EXPECT_EQ(tiny.Get(0, cameras[0], grid), nullptr) << "past the budget";
}

// A grid of many planes carved on one thread: TBB's default partitioner hands such a loop
// ranges of 8 planes or more, more than the support count's corner arrays hold (4); the
// slabs must stay thin (an overflow of those arrays on the stack, before).
TEST(VoxelCarving, AGridOfManyPlanesOnOneThreadIsCarvedInThinSlabs) {
  const Sphere sphere;
  const std::vector<Camera> cameras = SixCameras();
  const Bounds tall{sphere.centre - Eigen::Vector3d(0.02, 0.02, 0.12), sphere.centre + Eigen::Vector3d(0.02, 0.02, 0.12)};
  VoxelCarvingOptions options;
  options.resolution = 512;
  options.threads = 1;
  const CarvingResult result = CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), tall, options);
  EXPECT_EQ(result.occupancy.nz, 512);
  EXPECT_GT(result.carved_voxels, 0u);
}

TEST(VoxelCarving, BadCamerasAreExcludedWithAWarningAndTheRestIsCarved) {
  const Sphere sphere;
  std::vector<Camera> cameras = SixCameras();
  std::vector<Silhouette> silhouettes = SphereSilhouettes(cameras, sphere);
  VoxelCarvingOptions options;
  options.compute_silhouette_iou = false;
  const CarvingResult reference = CarveVoxels(cameras, silhouettes, kBounds, options, 7);

  // A camera looking away from the volume, and one whose silhouette is empty.
  cameras.push_back(LookAt("away", 160, 120, 200, Spherical(0.6, 0, 0), Spherical(2.0, 0, 0)));
  silhouettes.push_back(SilhouetteFromMask(cv::Mat::zeros(120, 160, CV_8UC1)));
  cameras.push_back(LookAt("blind", 160, 120, 200, Spherical(0.6, 150, 40), Eigen::Vector3d::Zero()));
  silhouettes.push_back(SilhouetteFromMask(cv::Mat::zeros(120, 160, CV_8UC1)));
  const CarvingResult result = CarveVoxels(cameras, silhouettes, kBounds, options, 7);
  ASSERT_EQ(result.warnings.size(), 2u);
  EXPECT_NE(result.warnings[0].find("\"away\" sees nothing of the working volume"), std::string::npos)
      << result.warnings[0];
  EXPECT_NE(result.warnings[1].find("frame 7: camera \"blind\" has an empty silhouette"), std::string::npos)
      << result.warnings[1];
  EXPECT_FALSE(result.cameras[6].used);
  EXPECT_FALSE(result.cameras[7].used);
  // Exact: the excluded cameras change nothing.
  EXPECT_EQ(result.occupancy.values, reference.occupancy.values);

  // Nothing usable: errors that say why.
  std::vector<Silhouette> all_empty(6, SilhouetteFromMask(cv::Mat::zeros(120, 160, CV_8UC1)));
  try {
    CarveVoxels(SixCameras(), all_empty, kBounds, options, 3);
    FAIL() << "all-empty silhouettes accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("every camera's silhouette is empty"), std::string::npos)
        << error.what();
  }
  const std::vector<Camera> away_only = {cameras[6]};
  EXPECT_THROW(CarveVoxels(away_only, {silhouettes[0]}, kBounds, options), Error);
  EXPECT_THROW(CarveVoxels(SixCameras(), {silhouettes[0]}, kBounds, options), Error);  // count mismatch
}

TEST(VoxelCarving, ObjectLeavingTheBoundsIsReportedWithFrameAndSideAndSummarizedOverATake) {
  const Sphere sphere;
  const std::vector<Camera> cameras = SixCameras();
  Bounds cut = kBounds;
  cut.max.x() = sphere.centre.x() + 0.5 * sphere.radius;  // the sphere sticks out at +x
  VoxelCarvingOptions options;
  options.resolution = 40;
  const CarvingResult result = CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), cut, options, 5);
  EXPECT_GT(result.border_voxels[1], 0u);
  EXPECT_EQ(result.border_voxels[0] + result.border_voxels[2] + result.border_voxels[3] +
                result.border_voxels[4] + result.border_voxels[5],
            0u);
  ASSERT_EQ(result.warnings.size(), 1u);
  EXPECT_NE(result.warnings[0].find("frame 5: the object touches the +x side"), std::string::npos)
      << result.warnings[0];

  // A take: one line per side over its frames, not one per frame (the same warning stays in
  // each frame's result, for report.json).
  std::vector<CarvingResult> take;
  for (int frame : {3, 4, 7}) take.push_back(CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), cut, options, frame));
  take.push_back(CarveVoxels(cameras, SphereSilhouettes(cameras, sphere), kBounds, options, 8));  // inside
  ASSERT_EQ(take[0].warnings.size(), 1u);
  std::vector<const CarvingResult*> frames;
  for (const CarvingResult& frame : take) frames.push_back(&frame);
  const std::vector<std::string> lines = SummarizeBorderContacts(frames);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("touches the +x side of the working volume in 3 of 4 frames (3–7; up to " +
                          std::to_string(result.border_voxels[1]) + " voxels)"),
            std::string::npos)
      << lines[0];
  EXPECT_TRUE(SummarizeBorderContacts({frames.back()}).empty());
}

TEST(VoxelCarving, OptionsAreChecked) {
  VoxelCarvingOptions options;
  EXPECT_NO_THROW(options.Check());
  options.connectivity = 8;
  try {
    options.Check();
    FAIL() << "connectivity 8 accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("connectivity"), std::string::npos);
  }
}

TEST(VoxelGrid, CoversTheBoundsWithCubicVoxels) {
  const Bounds bounds{Eigen::Vector3d(-1, -0.5, 0), Eigen::Vector3d(1, 0.5, 0.3)};
  const ScalarVolume grid = MakeVoxelGrid(bounds, 20);  // 0.1 voxels
  EXPECT_EQ(grid.nx, 20);
  EXPECT_EQ(grid.ny, 10);
  EXPECT_EQ(grid.nz, 3);
  EXPECT_DOUBLE_EQ(grid.spacing, 0.1);
  // Centred: the first and last voxel centres sit half a voxel inside the bounds.
  EXPECT_NEAR(grid.origin.x(), -0.95, 1e-12);
  EXPECT_NEAR(grid.VoxelCenter(19, 9, 2).x(), 0.95, 1e-12);
  EXPECT_NEAR(grid.origin.z(), 0.05, 1e-12);
}

// ---- the blob dataset (../shared/data/blob), frame 0, from each source of evidence ----

struct BlobFigures {
  double in_voxel_fraction = 0;  // GT vertices whose voxel (the cube containing them) is occupied
  double inside_fraction = 0;    // GT vertices inside the iso-surface at ½ (trilinear ≥ ½)
  double volume_ratio = 0;       // occupied volume / GT mesh volume
  double mask_iou = 0;           // projected occupancy vs the dataset's masks, mean over cameras
  CarvingResult result;
};

// Carves frame 0 of ../shared/data/blob (10 cameras, 320 × 240) from one source of
// evidence at 64 voxels along the longest axis (4.2 mm ≈ 3 px: modest, for test time) and
// measures it against the ground-truth mesh and the masks.
BlobFigures CarveBlob(EvidenceSource source, SilhouetteOptions silhouette_options = {}) {
  const Dataset dataset(SUBFLOW_SHARED_DIR "/data/blob");
  silhouette_options.source = source;
  VoxelCarvingOptions carving_options;
  carving_options.resolution = 64;
  BlobFigures figures;
  figures.result = CarveFrame(dataset, 0, silhouette_options, carving_options);
  const ScalarVolume& occupancy = figures.result.occupancy;
  const geometry::TriangleMesh truth = geometry::ReadMesh(dataset.GroundTruthMeshPath(0));
  size_t inside = 0, in_voxel = 0;
  for (int v = 0; v < truth.V.rows(); ++v) {
    const Eigen::Vector3d X = truth.V.row(v).transpose();
    inside += TrilinearOccupancy(occupancy, X) >= 0.5;
    const Eigen::Vector3d g = (X - occupancy.origin) / occupancy.spacing;
    const int i = static_cast<int>(std::lround(g.x())), j = static_cast<int>(std::lround(g.y())),
              k = static_cast<int>(std::lround(g.z()));
    in_voxel += occupancy.InRange(i, j, k) && occupancy.at(i, j, k) > 0.5f;
  }
  figures.inside_fraction = static_cast<double>(inside) / truth.V.rows();
  figures.in_voxel_fraction = static_cast<double>(in_voxel) / truth.V.rows();
  double volume = 0;  // divergence theorem over the closed GT mesh
  for (int f = 0; f < truth.F.rows(); ++f)
    volume += truth.V.row(truth.F(f, 0)).dot(truth.V.row(truth.F(f, 1)).cross(truth.V.row(truth.F(f, 2)))) / 6.0;
  figures.volume_ratio = figures.result.occupied_voxels * std::pow(occupancy.spacing, 3) / std::abs(volume);
  for (int c = 0; c < dataset.camera_count(); ++c)
    figures.mask_iou += SilhouetteIoU(ProjectOccupancy(dataset.camera(c), occupancy), dataset.Mask(c, 0)) /
                        dataset.camera_count();
  std::printf("[ figures ] blob frame 0 from %s: GT vertices in occupied voxels %.4f, inside the iso-surface "
              "%.4f; volume / GT volume %.3f; IoU vs masks %.4f (vs its own silhouettes %.4f); occupied %zu of "
              "%zu voxels; max_misses %d\n",
              ToString(source).c_str(), figures.in_voxel_fraction, figures.inside_fraction, figures.volume_ratio,
              figures.mask_iou, figures.result.mean_silhouette_iou, figures.result.occupied_voxels,
              occupancy.size(), figures.result.max_misses);
  for (const CameraCarvingReport& camera : figures.result.cameras) EXPECT_EQ(camera.source, source) << camera.name;
  return figures;
}

// The rest of the figures' tolerances follow from the conservative carving rule (see
// voxel_carving.h): the hull contains the object and exceeds it by the visual hull's own
// excess plus at most ~√3/2 voxel + 1 px (≈ 5 mm at 4.2 mm voxels, on a radius of 100 mm:
// a volume factor ≤ 1.05³ ≈ 1.16 over the hull), and the projected cubes are the
// silhouettes grown by ≈ 3–4 px (radius ≈ 70 px: IoU ≈ (70 / 74)² ≈ 0.9).
TEST(VoxelCarvingBlob, FromMasksContainsTheObject) {
  const BlobFigures figures = CarveBlob(EvidenceSource::kMask);
  EXPECT_TRUE(figures.result.warnings.empty());
  EXPECT_EQ(figures.result.max_misses, 0);
  // The masks are exact (coverage > ½ at pixel centres): every GT vertex lies in an
  // occupied voxel but for the last half pixel of sampling (≥ 99 %), and inside the
  // iso-surface at ½ (≥ 99.9 %).
  EXPECT_GE(figures.in_voxel_fraction, 0.99);
  EXPECT_GE(figures.inside_fraction, 0.999);
  EXPECT_GT(figures.volume_ratio, 1.0);
  EXPECT_LT(figures.volume_ratio, 1.2);
  EXPECT_GT(figures.mask_iou, 0.88);
}

// Plain background differences, with their contour moved to half coverage, match the
// masks to about half a pixel: the strict hull (max_misses 0) from them contains the
// object as the masks' does.
SilhouetteOptions PlainDifference() {
  SilhouetteOptions options;
  options.background_shadow_test = false;
  return options;
}

TEST(VoxelCarvingBlob, FromPlainBackgroundDifferenceContainsTheObject) {
  const BlobFigures figures = CarveBlob(EvidenceSource::kBackground, PlainDifference());
  EXPECT_EQ(figures.result.max_misses, 0);
  EXPECT_GE(figures.in_voxel_fraction, 0.99);
  EXPECT_GE(figures.inside_fraction, 0.99);
  EXPECT_GT(figures.volume_ratio, 1.0);
  EXPECT_LT(figures.volume_ratio, 1.2);  // as from the masks
  EXPECT_GT(figures.mask_iou, 0.88);
}

// The default, shadow-robust difference (vision/silhouettes_background.h): its hull is
// tighter and closer to the masks' than the plain difference's, and still holds the
// object inside its iso-surface. Not every true vertex keeps its voxel (0.981 of them
// against the plain difference's 0.993): where the object is darker than an untextured
// background by about a gain, one gain explains both (the limitation the header states).
TEST(VoxelCarvingBlob, FromShadowRobustDifferenceIsTighterAndHoldsTheObject) {
  const BlobFigures plain = CarveBlob(EvidenceSource::kBackground, PlainDifference());
  const BlobFigures figures = CarveBlob(EvidenceSource::kBackground);
  EXPECT_EQ(figures.result.max_misses, 0);
  EXPECT_GT(figures.mask_iou, plain.mask_iou);
  EXPECT_LT(figures.volume_ratio, plain.volume_ratio);
  EXPECT_GT(figures.volume_ratio, 1.0);
  EXPECT_GE(figures.inside_fraction, 0.99);  // as the plain difference's
}

// Motion evidence (eq. 23) accumulated over a window of frames 0..2 at the first frame:
// the silhouettes spread ~2 px beyond the contour (smoothing, ~1.4 px of motion over the
// central difference) and miss bites where weak texture moves along the contour;
// max_misses = 1 tolerates a bite in one camera per voxel, so a few vertices may fall outside.
SilhouetteOptions MotionWindow(int half_width) {
  SilhouetteOptions options;
  options.motion_window = half_width;
  return options;
}

TEST(VoxelCarvingBlob, FromMotionEvidenceOverAWindowNearlyContainsTheObject) {
  const BlobFigures figures = CarveBlob(EvidenceSource::kMotion, MotionWindow(2));
  EXPECT_EQ(figures.result.max_misses, 1);
  EXPECT_GE(figures.in_voxel_fraction, 0.95);
  EXPECT_GE(figures.inside_fraction, 0.97);
  EXPECT_GT(figures.volume_ratio, 1.0);
  EXPECT_LT(figures.volume_ratio, 1.3);
  EXPECT_GT(figures.mask_iou, 0.85);
}

// Without the window (the default), the silhouettes are not the union of the positions
// over five frames: the hull is tighter (closer to the masks, smaller volume).
TEST(VoxelCarvingBlob, FromMotionEvidenceOfOneFrameIsTighterThanOverAWindow) {
  const BlobFigures window = CarveBlob(EvidenceSource::kMotion, MotionWindow(2));
  const BlobFigures single = CarveBlob(EvidenceSource::kMotion, MotionWindow(0));
  EXPECT_GT(single.mask_iou, window.mask_iou);
  EXPECT_LT(single.volume_ratio, window.volume_ratio);
  EXPECT_GT(single.volume_ratio, 1.0);
  EXPECT_GE(single.in_voxel_fraction, 0.95);
}

}  // namespace
}  // namespace subflow::vision
