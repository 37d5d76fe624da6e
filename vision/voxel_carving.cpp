#include "vision/voxel_carving.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <opencv2/imgproc.hpp>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "core/error.h"
#include "vision/voxel_morphology.h"
#include "vision/voxel_projection.h"

namespace subflow::vision {
namespace {

using geometry::ScalarVolume;

// Whether the camera sees any point of a 17³ lattice over the bounds (corners included).
bool SeesVolume(const Camera& camera, const Bounds& bounds) {
  constexpr int kSteps = 16;
  for (int k = 0; k <= kSteps; ++k)
    for (int j = 0; j <= kSteps; ++j)
      for (int i = 0; i <= kSteps; ++i)
        if (ProjectsIntoImage(camera, bounds.min + bounds.Size().cwiseProduct(Eigen::Vector3d(i, j, k) / kSteps)))
          return true;
  return false;
}

struct CarvingCamera {
  int index = 0;
  cv::Mat integral;  // CV_64F (h + 1) × (w + 1) summed-area table of the evidence
};

// Sum of the evidence over pixels [x0, x1] × [y0, y1] (inclusive) from a summed-area table.
inline double BoxSum(const double* sums, size_t stride, int x0, int x1, int y0, int y1) {
  return sums[(y1 + 1) * stride + x1 + 1] - sums[y0 * stride + x1 + 1] - sums[(y1 + 1) * stride + x0] +
         sums[y0 * stride + x0];
}

// Counts, for every voxel, the cameras that see it and support it (hits) or not (misses).
// Voxels with more than max_misses misses are skipped by later cameras (already carved).
// Tasks are slabs of 4 z-slices, visited in blocks of kBlock × kBlock voxels.
//
// Speed-up, exact: for a pinhole camera, a block of up to kBlock × kBlock voxels of the
// slab is first tested as a whole. The footprint of every voxel in it lies in the block's
// footprint (the bounding box of the block's 8 projected corners: perspective maps the
// box to the convex hull of its corners), so when the block's footprint is inside the
// image and its pixels — grown by one pixel to cover the nearest-pixel rule — have
// evidence all 0 (mean 0) or all 1 (mean = 1), every voxel is a miss or a hit without
// looking at it. Only blocks straddling the silhouette's contour are visited voxel by
// voxel, so the cost follows the object's surface, not its volume.
// A distorted camera whose corners are kept (kept[u] for used[u], may be null) takes them
// from there, and is tested block by block on the box of all the block's corners (its
// edges curve: the outer 8 do not bound it).
void CountSupport(const std::vector<Camera>& cameras, const std::vector<CarvingCamera>& used,
                  const std::vector<const GridCornerPixels*>& kept, const ScalarVolume& grid, double threshold,
                  float margin, int max_misses, std::vector<uint16_t>* hits, std::vector<uint16_t>* misses) {
  constexpr int kSlab = 4, kBlock = 8;
  // The simple partitioner: slabs of at most kSlab planes, as the corner arrays below hold
  // (the default partitioner may hand out larger ranges).
  tbb::parallel_for(tbb::blocked_range<int>(0, grid.nz, kSlab), [&](const tbb::blocked_range<int>& range) {
    const int k0 = range.begin(), k1 = range.end();
    SUBFLOW_CHECK(k1 - k0 <= kSlab, "a slab thicker than the corner arrays");
    constexpr size_t kCorners = (kBlock + 1) * (kBlock + 1) * (kSlab + 1);
    float us[kCorners], vs[kCorners];
    for (std::size_t u = 0; u < used.size(); ++u) {
      const CarvingCamera& carving_camera = used[u];
      const Camera& camera = cameras[carving_camera.index];
      const GridCornerPixels* corner_pixels = kept[u];
      const int width = camera.width(), height = camera.height();
      const double* sums = carving_camera.integral.ptr<double>();
      const size_t stride = width + 1;
      const bool pinhole = !camera.HasDistortion();
      const VoxelCornerProjector projector(camera, grid);
      // Whether a box of pixel coordinates lies inside the image: false too when one of the
      // corners it bounds is behind the camera (kInvalidPixel).
      auto inside = [&](float x_min, float x_max, float y_min, float y_max) {
        return x_min >= -0.5f && y_min >= -0.5f && x_max < width - 0.5f && y_max < height - 0.5f;
      };
      // Bounding box of the projections of 8 corners (indices into us / vs), and whether it
      // is inside the image.
      auto footprint = [&](const size_t* corners, float* x_min, float* x_max, float* y_min, float* y_max) {
        *x_min = *x_max = us[corners[0]];
        *y_min = *y_max = vs[corners[0]];
        for (int c = 1; c < 8; ++c) {
          *x_min = std::min(*x_min, us[corners[c]]);
          *x_max = std::max(*x_max, us[corners[c]]);
          *y_min = std::min(*y_min, vs[corners[c]]);
          *y_max = std::max(*y_max, vs[corners[c]]);
        }
        return inside(*x_min, *x_max, *y_min, *y_max);
      };
      for (int j_begin = 0; j_begin < grid.ny; j_begin += kBlock)
        for (int i_begin = 0; i_begin < grid.nx; i_begin += kBlock) {
          const int j_end = std::min(j_begin + kBlock, grid.ny), i_end = std::min(i_begin + kBlock, grid.nx);
          const size_t row = i_end - i_begin + 1, plane = row * (j_end - j_begin + 1);
          // Every voxel of the block a hit (or a miss) when the evidence over the block's
          // footprint (x_min..y_max) grown by the margin is all 1 (or all 0).
          auto whole_block = [&](float x_min, float x_max, float y_min, float y_max) {
            const int x0 = std::max(0, static_cast<int>(std::floor(x_min - margin)));
            const int x1 = std::min(width - 1, static_cast<int>(std::ceil(x_max + margin)));
            const int y0 = std::max(0, static_cast<int>(std::floor(y_min - margin)));
            const int y1 = std::min(height - 1, static_cast<int>(std::ceil(y_max + margin)));
            const double sum = BoxSum(sums, stride, x0, x1, y0, y1);
            const double area = static_cast<double>(x1 - x0 + 1) * (y1 - y0 + 1);
            if (sum > 0 && sum < area) return false;
            std::vector<uint16_t>& counts = sum <= 0 ? *misses : *hits;
            for (int k = k0; k < k1; ++k)
              for (int j = j_begin; j < j_end; ++j)
                for (size_t v = grid.Index(i_begin, j, k), end = v + (i_end - i_begin); v < end; ++v) ++counts[v];
            return true;
          };
          float x_min, x_max, y_min, y_max;
          if (pinhole) {
            // The block's 8 outer corners, stored where the block's full corner grid would put them.
            const size_t di = row - 1, dj = plane - row, dk = (k1 - k0) * plane;
            const size_t corners[8] = {0, di, dj, di + dj, dk, dk + di, dk + dj, dk + di + dj};
            for (size_t c : corners)
              projector.ProjectCorner(i_begin + (c % row), j_begin + (c % plane) / row, k0 + c / plane, &us[c], &vs[c]);
            if (footprint(corners, &x_min, &x_max, &y_min, &y_max) && whole_block(x_min, x_max, y_min, y_max)) continue;
            projector.ProjectCorners(i_begin, i_end, j_begin, j_end, k0, k1, us, vs);
          } else if (corner_pixels) {
            size_t c = 0;
            for (int k = k0; k <= k1; ++k)
              for (int j = j_begin; j <= j_end; ++j) {
                const size_t first = corner_pixels->Index(i_begin, j, k);
                std::copy_n(corner_pixels->u.data() + first, row, us + c);
                std::copy_n(corner_pixels->v.data() + first, row, vs + c);
                c += row;
              }
            x_min = *std::min_element(us, us + c), x_max = *std::max_element(us, us + c);
            y_min = *std::min_element(vs, vs + c), y_max = *std::max_element(vs, vs + c);
            if (inside(x_min, x_max, y_min, y_max) && whole_block(x_min, x_max, y_min, y_max)) continue;
          } else {
            projector.ProjectCorners(i_begin, i_end, j_begin, j_end, k0, k1, us, vs);
          }
          for (int k = k0; k < k1; ++k)
            for (int j = j_begin; j < j_end; ++j)
              for (int i = i_begin; i < i_end; ++i) {
                const size_t voxel = grid.Index(i, j, k);
                if ((*misses)[voxel] > max_misses) continue;
                const size_t c0 = (k - k0) * plane + (j - j_begin) * row + (i - i_begin);
                const size_t corners[8] = {c0,         c0 + 1,         c0 + row,         c0 + row + 1,
                                           c0 + plane, c0 + plane + 1, c0 + plane + row, c0 + plane + row + 1};
                float x_min, x_max, y_min, y_max;
                if (!footprint(corners, &x_min, &x_max, &y_min, &y_max)) continue;
                // Pixels whose centres lie in the footprint grown by the margin (clipped to
                // the image); per axis the nearest when none does.
                int x0 = std::max(0, static_cast<int>(std::ceil(x_min - margin)));
                int x1 = std::min(width - 1, static_cast<int>(std::floor(x_max + margin)));
                int y0 = std::max(0, static_cast<int>(std::ceil(y_min - margin)));
                int y1 = std::min(height - 1, static_cast<int>(std::floor(y_max + margin)));
                if (x0 > x1) x0 = x1 = std::clamp(static_cast<int>(std::lround(0.5f * (x_min + x_max))), 0, width - 1);
                if (y0 > y1) y0 = y1 = std::clamp(static_cast<int>(std::lround(0.5f * (y_min + y_max))), 0, height - 1);
                const double area = static_cast<double>(x1 - x0 + 1) * (y1 - y0 + 1);
                if (BoxSum(sums, stride, x0, x1, y0, y1) >= threshold * area) ++(*hits)[voxel];
                else ++(*misses)[voxel];
              }
        }
    }
  }, tbb::simple_partitioner());
}

std::string FrameLabel(int frame) { return "frame " + std::to_string(frame); }

void Warn(CarvingResult* result, const std::string& message, spdlog::level::level_enum level = spdlog::level::warn) {
  spdlog::log(level, "{}", message);
  result->warnings.push_back(message);
}

// The automatic values, by the used cameras' evidence: max_misses 1 when some silhouette
// comes from motion, else 0; closing and opening radii 0 when every one is the object's
// outline (a mask, or Silhouette::outline), else 1.
void ResolveBySources(const std::vector<CarvingCamera>& used, const std::vector<Silhouette>& silhouettes,
                      const VoxelCarvingOptions& options, CarvingResult* result) {
  bool any_motion = false, all_outlines = true;
  for (const CarvingCamera& c : used) {
    const Silhouette& silhouette = silhouettes[c.index];
    any_motion = any_motion || silhouette.source == EvidenceSource::kMotion;
    all_outlines = all_outlines && (silhouette.source == EvidenceSource::kMask || silhouette.outline);
  }
  result->max_misses = options.max_misses >= 0 ? options.max_misses : (any_motion ? 1 : 0);
  result->closing_radius = options.closing_radius >= 0 ? options.closing_radius : (all_outlines ? 0 : 1);
  result->opening_radius = options.opening_radius >= 0 ? options.opening_radius : (all_outlines ? 0 : 1);
}

}  // namespace

const char* const kBorderSides[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};

std::vector<std::string> SummarizeBorderContacts(const std::vector<const CarvingResult*>& frames) {
  std::vector<std::string> lines;
  for (int side = 0; side < 6; ++side) {
    int touching = 0, first = 0, last = 0;
    std::size_t most = 0;
    for (const CarvingResult* frame : frames) {
      if (frame->border_voxels[side] == 0) continue;
      if (touching++ == 0) first = frame->frame;
      last = frame->frame;
      most = std::max(most, frame->border_voxels[side]);
    }
    if (touching == 0) continue;
    lines.push_back(fmt::format("the object touches the {} side of the working volume in {} of {} frames ({}–{}; up "
                                "to {} voxels): it may extend beyond the bounds (report.json: "
                                "shape_init.frames[].border_voxels)",
                                kBorderSides[side], touching, frames.size(), first, last, most));
  }
  return lines;
}

void VoxelCarvingOptions::Check() const {
  auto fail = [](const char* field, const std::string& expected, double value) {
    ThrowError("VoxelCarvingOptions", field, "expected " + expected + ", got " + std::to_string(value));
  };
  if (resolution < 0 || resolution > 2048) fail("resolution", "0 (automatic) or 1..2048", resolution);
  if (!(pixels_per_voxel > 0 && pixels_per_voxel <= 1000)) fail("pixels_per_voxel", "a value in (0, 1000]", pixels_per_voxel);
  if (max_auto_resolution < 8 || max_auto_resolution > 2048) fail("max_auto_resolution", "8..2048", max_auto_resolution);
  if (!(max_pixels_per_voxel == 0 || max_pixels_per_voxel >= 1))
    fail("max_pixels_per_voxel", "0 (stored size) or at least 1", max_pixels_per_voxel);
  if (min_cameras < 1) fail("min_cameras", "at least 1", min_cameras);
  if (max_misses < -1) fail("max_misses", "-1 (automatic) or ≥ 0", max_misses);
  if (!(evidence_threshold > 0 && evidence_threshold <= 1)) fail("evidence_threshold", "a value in (0, 1]", evidence_threshold);
  if (!(footprint_margin >= 0 && footprint_margin <= 100)) fail("footprint_margin", "a value in [0, 100] pixels", footprint_margin);
  if (closing_radius < -1 || closing_radius > 32) fail("closing_radius", "-1 (automatic) or 0..32 voxels", closing_radius);
  if (opening_radius < -1 || opening_radius > 32) fail("opening_radius", "-1 (automatic) or 0..32 voxels", opening_radius);
  if (connectivity != 6 && connectivity != 26) fail("connectivity", "6 or 26", connectivity);
  if (!(min_component_fraction >= 0 && min_component_fraction <= 1)) fail("min_component_fraction", "a value in [0, 1]", min_component_fraction);
  if (threads < 0) fail("threads", "0 (all) or a positive count", threads);
}

double AutomaticVoxelSpacing(const std::vector<Camera>& cameras, const Bounds& bounds,
                             const VoxelCarvingOptions& options) {
  double finest = 0;  // pixels per world unit at the centre, best camera
  const Eigen::Vector3d centre = bounds.Center();
  for (const Camera& camera : cameras) {
    if (!ProjectsIntoImage(camera, centre)) continue;
    const double focal = 0.5 * (camera.K()(0, 0) + camera.K()(1, 1));
    finest = std::max(finest, focal / camera.ToCamera(centre).z());
  }
  return finest > 0 ? options.pixels_per_voxel / finest : 0.0;
}

int ChooseResolution(const std::vector<Camera>& cameras, const Bounds& bounds,
                     const VoxelCarvingOptions& options) {
  if (options.resolution > 0) return options.resolution;
  const double spacing = AutomaticVoxelSpacing(cameras, bounds, options);
  if (spacing <= 0) return options.max_auto_resolution;
  const double voxels = std::ceil(bounds.Size().maxCoeff() / spacing);
  return static_cast<int>(std::clamp(voxels, 8.0, static_cast<double>(options.max_auto_resolution)));
}

VoxelCarvingOptions ResolveCarvingOptions(const std::vector<Camera>& cameras, const Bounds& bounds,
                                          const VoxelCarvingOptions& options) {
  options.Check();
  if (!bounds.IsValid()) ThrowError("", "bounds", "expected min < max (finite) on every axis");
  VoxelCarvingOptions resolved = options;
  resolved.resolution = ChooseResolution(cameras, bounds, options);
  const double automatic = AutomaticVoxelSpacing(cameras, bounds, options);
  const double spacing = bounds.Size().maxCoeff() / resolved.resolution;
  if (automatic > 0 && spacing > automatic) {
    const auto narrow = [&](int radius) {
      const auto narrowed = [&](int r) { return std::min(r, static_cast<int>(std::floor(r * automatic / spacing + 0.5))); };
      // Automatic stays automatic unless even its largest choice (1) narrows to 0.
      return radius >= 0 ? narrowed(radius) : (narrowed(1) >= 1 ? -1 : 0);
    };
    resolved.closing_radius = narrow(options.closing_radius);
    resolved.opening_radius = narrow(options.opening_radius);
  }
  return resolved;
}

ScalarVolume MakeVoxelGrid(const Bounds& bounds, int resolution) {
  if (!bounds.IsValid()) ThrowError("", "bounds", "expected min < max (finite) on every axis");
  SUBFLOW_CHECK(resolution >= 1, "resolution must be positive");
  const double spacing = bounds.Size().maxCoeff() / resolution;
  Eigen::Vector3i counts;
  for (int a = 0; a < 3; ++a)
    counts[a] = std::max(1, static_cast<int>(std::ceil(bounds.Size()[a] / spacing - 1e-9)));
  const Eigen::Vector3d origin = bounds.Center() - 0.5 * spacing * (counts.cast<double>() - Eigen::Vector3d::Ones());
  return ScalarVolume(origin, spacing, counts[0], counts[1], counts[2], 0.0f);
}

const GridCornerPixels* CornerPixelCache::Get(int index, const Camera& camera, const ScalarVolume& grid) {
  if (!camera.HasDistortion()) return nullptr;
  const std::vector<double> key = {grid.origin.x(), grid.origin.y(), grid.origin.z(), grid.spacing,
                                   double(grid.nx), double(grid.ny), double(grid.nz)};
  if (key != grid_) {  // another grid: nothing kept applies
    grid_ = key;
    cameras_.clear();
    bytes_ = 0;
  }
  const auto kept = cameras_.find(index);
  if (kept != cameras_.end()) return &kept->second;
  const std::size_t bytes = 2 * sizeof(float) * std::size_t(grid.nx + 1) * (grid.ny + 1) * (grid.nz + 1);
  if (bytes_ + bytes > budget_) return nullptr;
  bytes_ += bytes;
  return &cameras_.emplace(index, ProjectGridCorners(camera, grid)).first->second;
}

CarvingResult CarveVoxels(const std::vector<Camera>& cameras,
                          const std::vector<Silhouette>& silhouettes, const Bounds& bounds,
                          const VoxelCarvingOptions& options, int frame, CornerPixelCache* corners) {
  options.Check();
  const std::string where = FrameLabel(frame);
  if (silhouettes.size() != cameras.size())
    ThrowError(where, "silhouettes", "expected one per camera (" + std::to_string(cameras.size()) +
                                         "), got " + std::to_string(silhouettes.size()));
  if (!bounds.IsValid()) ThrowError(where, "bounds", "expected min < max (finite) on every axis");

  CarvingResult result;
  result.frame = frame;
  std::vector<CarvingCamera> used;
  int empty_count = 0, seeing_count = 0;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const Camera& camera = cameras[c];
    const Silhouette& silhouette = silhouettes[c];
    CameraCarvingReport report;
    report.name = camera.name();
    report.source = silhouette.source;
    report.object_pixels = silhouette.object_pixels;
    report.threshold = silhouette.threshold;
    if (silhouette.evidence.type() != CV_32FC1 || silhouette.evidence.cols != camera.width() ||
        silhouette.evidence.rows != camera.height())
      ThrowError(where, "camera \"" + camera.name() + "\": silhouette",
                 "expected a CV_32FC1 evidence image of " + std::to_string(camera.width()) + "×" +
                     std::to_string(camera.height()) + " pixels");
    if (!SeesVolume(camera, bounds)) {
      report.excluded = "sees nothing of the working volume";
      Warn(&result, where + ": camera \"" + camera.name() +
                        "\" sees nothing of the working volume: excluded");
    } else if (silhouette.empty) {
      ++seeing_count;
      ++empty_count;
      report.excluded = "empty silhouette";
      Warn(&result, where + ": camera \"" + camera.name() + "\" has an empty silhouette (" +
                        ToString(silhouette.source) +
                        "): excluded, it would carve away every voxel it sees");
    } else {
      ++seeing_count;
      report.used = true;
      CarvingCamera carving_camera;
      carving_camera.index = static_cast<int>(c);
      cv::integral(silhouette.evidence, carving_camera.integral, CV_64F);
      used.push_back(std::move(carving_camera));
    }
    result.cameras.push_back(report);
  }
  if (seeing_count == 0)
    ThrowError(where, "cameras", "no camera sees the working volume: nothing can be carved");
  if (used.empty())
    ThrowError(where, "silhouettes", "every camera's silhouette is empty (" +
                                         std::to_string(empty_count) + " cameras): cannot find the object");
  if (static_cast<int>(used.size()) < options.min_cameras)
    ThrowError(where, "cameras", "only " + std::to_string(used.size()) +
                                     " camera(s) usable, min_cameras = " + std::to_string(options.min_cameras));

  ResolveBySources(used, silhouettes, options, &result);
  result.resolution = ChooseResolution(cameras, bounds, options);
  result.occupancy = MakeVoxelGrid(bounds, result.resolution);
  ScalarVolume& occupancy = result.occupancy;

  BinaryVolume occupied(occupancy.nx, occupancy.ny, occupancy.nz);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic : options.threads);
  arena.execute([&] {
    std::vector<uint16_t> hits(occupancy.size(), 0), misses(occupancy.size(), 0);
    std::vector<const GridCornerPixels*> kept(used.size(), nullptr);
    if (corners)
      for (std::size_t u = 0; u < used.size(); ++u) kept[u] = corners->Get(used[u].index, cameras[used[u].index], occupancy);
    CountSupport(cameras, used, kept, occupancy, options.evidence_threshold,
                 static_cast<float>(options.footprint_margin), result.max_misses, &hits, &misses);
    for (size_t v = 0; v < occupancy.size(); ++v)
      occupied.values[v] = hits[v] >= options.min_cameras && misses[v] <= result.max_misses;
    result.carved_voxels = occupied.Count();
    CloseBox(&occupied, result.closing_radius);
    OpenBox(&occupied, result.opening_radius);
    const ComponentSummary components =
        KeepLargeComponents(&occupied, options.min_component_fraction, options.connectivity);
    result.components_found = components.found;
    result.components_kept = components.kept;
    if (options.fill_cavities) result.cavity_voxels_filled = FillCavities(&occupied, options.connectivity);
    occupied.CopyTo(&occupancy);
    if (options.compute_silhouette_iou) {
      const std::vector<Eigen::Vector3i> surface = SurfaceVoxels(occupancy);
      tbb::parallel_for(size_t(0), used.size(), [&](size_t u) {
        const int c = used[u].index;
        const cv::Mat mask = silhouettes[c].mask.type() == CV_8UC1 &&
                                     silhouettes[c].mask.size() == silhouettes[c].evidence.size()
                                 ? silhouettes[c].mask
                                 : cv::Mat(silhouettes[c].evidence >= 0.5f);
        result.cameras[c].silhouette_iou = SilhouetteIoU(ProjectVoxels(cameras[c], occupancy, surface), mask);
      });
    }
  });

  result.occupied_voxels = occupied.Count();
  if (result.occupied_voxels == 0)
    Warn(&result, where + ": no voxel is occupied: the silhouettes do not agree on any object");
  for (int k = 0; k < occupancy.nz; ++k)
    for (int j = 0; j < occupancy.ny; ++j)
      for (int i = 0; i < occupancy.nx; ++i) {
        if (occupancy.at(i, j, k) <= 0.5f) continue;
        result.border_voxels[0] += i == 0, result.border_voxels[1] += i == occupancy.nx - 1;
        result.border_voxels[2] += j == 0, result.border_voxels[3] += j == occupancy.ny - 1;
        result.border_voxels[4] += k == 0, result.border_voxels[5] += k == occupancy.nz - 1;
      }
  for (int side = 0; side < 6; ++side)
    if (result.border_voxels[side] > 0)
      Warn(&result,
           where + ": the object touches the " + kBorderSides[side] + " side of the working volume (" +
               std::to_string(result.border_voxels[side]) + " voxels): it may extend beyond the bounds",
           spdlog::level::debug);  // summarized over the take (SummarizeBorderContacts)
  if (options.compute_silhouette_iou) {
    double sum = 0;
    for (const CarvingCamera& c : used) sum += result.cameras[c.index].silhouette_iou;
    result.mean_silhouette_iou = sum / used.size();
  }
  return result;
}

}  // namespace subflow::vision
