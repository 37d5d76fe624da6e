#include "vision/concavity_carving.h"

#include <algorithm>
#include <array>

#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "vision/voxel_morphology.h"
#include "vision/voxel_projection.h"
#include "vision/working_scale.h"
#include "vision/working_volume.h"

namespace subflow::vision {
namespace {

std::size_t CountOccupied(const geometry::ScalarVolume& grid) {
  return static_cast<std::size_t>(std::count_if(grid.values.begin(), grid.values.end(), [](float v) { return v > 0.5f; }));
}

// The box of the occupied voxels' cubes, grown by one voxel; invalid when none is occupied.
Bounds OccupiedBounds(const geometry::ScalarVolume& grid) {
  Eigen::Vector3i low(grid.nx, grid.ny, grid.nz), high(-1, -1, -1);
  for (int k = 0; k < grid.nz; ++k)
    for (int j = 0; j < grid.ny; ++j)
      for (int i = 0; i < grid.nx; ++i)
        if (grid.at(i, j, k) > 0.5f) {
          low = low.cwiseMin(Eigen::Vector3i(i, j, k));
          high = high.cwiseMax(Eigen::Vector3i(i, j, k));
        }
  Bounds bounds;
  if (high.x() < 0) return bounds;
  bounds.min = grid.VoxelCenter(low.x(), low.y(), low.z()) - Eigen::Vector3d::Constant(1.5 * grid.spacing);
  bounds.max = grid.VoxelCenter(high.x(), high.y(), high.z()) + Eigen::Vector3d::Constant(1.5 * grid.spacing);
  return bounds;
}

// Keeps emptied (of what free space emptied in `hull`; `carved` = the hull after it) the
// voxels of the opening of the empty space — outside the hull and emptied — by a box of
// radius r: free space that a box fits in. The hull's margin trimmed along its surface and
// a hollow opened to the outside stay empty; narrow tunnels and pockets — one camera pair's
// wrong depths inside the object — are filled again.
void KeepWideCarving(const geometry::ScalarVolume& hull, int radius, geometry::ScalarVolume* carved) {
  BinaryVolume empty(hull.nx, hull.ny, hull.nz);
  for (std::size_t i = 0; i < hull.values.size(); ++i) empty.values[i] = carved->values[i] <= 0.5f;
  OpenBox(&empty, radius);
  for (std::size_t i = 0; i < hull.values.size(); ++i)
    if (hull.values[i] > 0.5f && carved->values[i] <= 0.5f && !empty.values[i]) carved->values[i] = 1.0f;
}

// Refills the emptied regions (of `hull`; `carved` = the hull after carving) that stay
// within `depth` voxels of the hull's outside: connected regions (26-neighbours) of
// emptied voxels none of which lies `depth` or more face-steps inside the hull. What is
// left is hollows; the hull's margin (about a voxel over the object) is left to the
// refinement, which corrects it from the images anyway.
void KeepDeepCarving(const geometry::ScalarVolume& hull, int depth, geometry::ScalarVolume* carved) {
  const int nx = hull.nx, ny = hull.ny, nz = hull.nz;
  const std::size_t size = hull.values.size();
  // Face-steps from the outside of the hull (breadth first from every empty voxel; the
  // grid's border counts as outside).
  std::vector<int> steps(size, -1);
  std::vector<std::size_t> queue;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t index = hull.Index(i, j, k);
        const bool border = i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1;
        if (hull.values[index] <= 0.5f) steps[index] = 0, queue.push_back(index);
        else if (border) steps[index] = 1, queue.push_back(index);
      }
  const std::array<int, 6> di{1, -1, 0, 0, 0, 0}, dj{0, 0, 1, -1, 0, 0}, dk{0, 0, 0, 0, 1, -1};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t index = queue[head];
    const int i = static_cast<int>(index % nx), j = static_cast<int>(index / nx % ny), k = static_cast<int>(index / nx / ny);
    for (int n = 0; n < 6; ++n) {
      if (!hull.InRange(i + di[n], j + dj[n], k + dk[n])) continue;
      const std::size_t next = hull.Index(i + di[n], j + dj[n], k + dk[n]);
      if (steps[next] < 0) steps[next] = steps[index] + 1, queue.push_back(next);
    }
  }
  // Emptied regions, each kept when it reaches `depth`.
  const auto emptied = [&](std::size_t index) { return hull.values[index] > 0.5f && carved->values[index] <= 0.5f; };
  std::vector<char> seen(size, 0);
  std::vector<std::size_t> region;
  for (std::size_t start = 0; start < size; ++start) {
    if (seen[start] || !emptied(start)) continue;
    region.assign(1, start);
    seen[start] = 1;
    bool deep = false;
    for (std::size_t head = 0; head < region.size(); ++head) {
      const std::size_t index = region[head];
      deep = deep || steps[index] >= depth;
      const int i = static_cast<int>(index % nx), j = static_cast<int>(index / nx % ny), k = static_cast<int>(index / nx / ny);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            if (!hull.InRange(i + dx, j + dy, k + dz)) continue;
            const std::size_t next = hull.Index(i + dx, j + dy, k + dz);
            if (!seen[next] && emptied(next)) seen[next] = 1, region.push_back(next);
          }
    }
    if (!deep)
      for (std::size_t index : region) carved->values[index] = 1.0f;
  }
}

}  // namespace

void ConcavityCarvingOptions::Check() const {
  sweep.Check();
  fusion.Check();
  if (!(max_carved_fraction > 0 && max_carved_fraction <= 1))
    ThrowError("concavity carving options", "max_carved_fraction", "expected a fraction in (0, 1]");
  if (min_neighbours < 1 || min_neighbours > sweep.neighbours)
    ThrowError("concavity carving options", "min_neighbours", "expected 1..sweep.neighbours");
  if (!(surface_margin_voxels >= 0 && surface_margin_voxels <= 100))
    ThrowError("concavity carving options", "surface_margin_voxels", "expected a value in [0, 100] voxels");
  if (min_depth < 0 || min_depth > 100) ThrowError("concavity carving options", "min_depth", "expected 0..100 voxels");
  if (opening_radius < 0 || opening_radius > 8)
    ThrowError("concavity carving options", "opening_radius", "expected 0..8 voxels");
  if (!(pixels_per_voxel >= 0 && pixels_per_voxel <= 100))
    ThrowError("concavity carving options", "pixels_per_voxel", "expected 0 (the images' size) or a value in (0, 100]");
  if (!(min_component_fraction >= 0 && min_component_fraction <= 1))
    ThrowError("concavity carving options", "min_component_fraction", "expected a value in [0, 1]");
}

ConcavityCarvingReport CarveConcavities(const std::vector<Camera>& cameras, const std::vector<cv::Mat>& gray,
                                        const ConcavityCarvingOptions& options, geometry::ScalarVolume* occupancy) {
  options.Check();
  const Stopwatch start;
  ConcavityCarvingReport report;
  if (gray.size() != cameras.size())
    ThrowError("concavity carving", "images", fmt::format("expected one image per camera ({}), got {}",
                                                          cameras.size(), gray.size()));
  report.hull_voxels = CountOccupied(*occupancy);
  const Bounds box = OccupiedBounds(*occupancy);
  if (!box.IsValid() || cameras.size() < 2) {
    report.skipped = !box.IsValid() ? "empty hull" : "fewer than 2 cameras";
    report.seconds = start.Seconds();
    return report;
  }
  const std::size_t count = cameras.size();
  // The rig must have at least 2 cameras with min_neighbours neighbours (then every
  // camera measures).
  int dense = 0;
  for (std::size_t k = 0; k < count; ++k)
    dense += static_cast<int>(ChooseNeighbours(cameras, static_cast<int>(k), options.sweep).size()) >=
             options.min_neighbours;
  if (dense < 2) {
    report.skipped = fmt::format("fewer than 2 cameras have {} neighbours within {}° to compare with",
                                 options.min_neighbours, options.sweep.max_neighbour_degrees);
    report.seconds = start.Seconds();
    return report;
  }
  std::vector<double> scales(count, 1.0);
  for (std::size_t k = 0; k < count; ++k)
    scales[k] = EvidenceScale(cameras[k], box, occupancy->spacing, options.pixels_per_voxel);
  const std::vector<Camera> swept = ScaledCameras(cameras, scales);
  std::vector<cv::Mat> images(count), known(count);
  for (std::size_t k = 0; k < count; ++k) {
    if (gray[k].size() != cv::Size(cameras[k].width(), cameras[k].height()) || gray[k].type() != CV_32FC1)
      ThrowError("concavity carving", "image of camera " + cameras[k].name(),
                 fmt::format("expected CV_32FC1 of {}x{}", cameras[k].width(), cameras[k].height()));
    images[k] = ResizeToCamera(gray[k], swept[k]);
    known[k] = ProjectOccupancy(swept[k], *occupancy);
  }
  const std::vector<DepthMap> maps = SweepDepthMaps(swept, images, box, options.sweep, known);
  const std::vector<cv::Mat> trusted = TrustedDepths(swept, maps, options.fusion);
  std::vector<double> steps(count);
  for (std::size_t k = 0; k < count; ++k) {
    spdlog::debug("concavity sweep {}: {} planes, {} neighbours, {:.3f} s", cameras[k].name(), maps[k].planes,
                  maps[k].neighbours.size(), maps[k].seconds);
    steps[k] = maps[k].inverse_depth_step;
    report.trusted_pixels += cv::countNonZero(trusted[k] >= 0);
  }
  geometry::ScalarVolume carved = *occupancy;
  report.carved_voxels = CarveSeenThrough(swept, trusted, steps, options.fusion,
                                          options.surface_margin_voxels * occupancy->spacing,
                                          options.surface_veto, &carved);
  if (report.carved_voxels > 0) {
    if (options.opening_radius > 0) KeepWideCarving(*occupancy, options.opening_radius, &carved);
    if (options.min_depth > 0) KeepDeepCarving(*occupancy, options.min_depth, &carved);
    KeepLargeComponents(&carved, options.min_component_fraction);
    FillCavities(&carved);
    const std::size_t after = CountOccupied(carved);
    report.removed_voxels = report.hull_voxels - std::min(report.hull_voxels, after);
    if (report.removed_voxels > options.max_carved_fraction * report.hull_voxels) {
      report.skipped = fmt::format("would remove {} of {} hull voxels (more than max_carved_fraction {})",
                                   report.removed_voxels, report.hull_voxels, options.max_carved_fraction);
    } else {
      *occupancy = std::move(carved);
      report.applied = true;
    }
  }
  report.seconds = start.Seconds();
  return report;
}

}  // namespace subflow::vision
