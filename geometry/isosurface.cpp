// The CGAL-free steps of iso-surface extraction: validation, padding, Gaussian blur and
// the search for seeds on every connected component. Mesh_3 lives in isosurface_cgal.cpp.
#include "geometry/isosurface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace subflow::geometry {
namespace {

void CheckFinitePositive(double value, const char* field, const char* what) {
  if (!std::isfinite(value) || value <= 0.0)
    ThrowError("IsosurfaceOptions", field,
               std::string("expected a finite ") + what + " > 0, got " + std::to_string(value));
}

// Gaussian kernel of standard deviation sigma, truncated at 3σ, normalized to sum 1.
std::vector<double> GaussianKernel(double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<double> kernel(2 * radius + 1);
  double sum = 0.0;
  for (int t = -radius; t <= radius; ++t) {
    kernel[t + radius] = std::exp(-0.5 * t * t / (sigma * sigma));
    sum += kernel[t + radius];
  }
  for (double& w : kernel) w /= sum;
  return kernel;
}

// Convolves `volume` along axis (0 = x, 1 = y, 2 = z) with `kernel`; zero outside. Rows
// along x are contiguous, so the y and z passes accumulate whole rows (cache friendly).
void ConvolveAxis(ScalarVolume* volume, int axis, const std::vector<double>& kernel) {
  const int radius = static_cast<int>(kernel.size() / 2);
  const int nx = volume->nx, ny = volume->ny, nz = volume->nz;
  const std::vector<float> input = volume->values;
  std::vector<float>& output = volume->values;
  if (axis == 0) {
    for (size_t row = 0; row < static_cast<size_t>(ny) * nz; ++row) {
      const float* in = &input[row * nx];
      float* out = &output[row * nx];
      for (int i = 0; i < nx; ++i) {
        double sum = 0.0;
        const int lo = std::max(0, i - radius), hi = std::min(nx - 1, i + radius);
        for (int t = lo; t <= hi; ++t) sum += kernel[t - i + radius] * in[t];
        out[i] = static_cast<float>(sum);
      }
    }
    return;
  }
  const int n = axis == 1 ? ny : nz;               // length along the axis
  const int m = axis == 1 ? nz : 1;                // independent slabs
  const size_t stride = axis == 1 ? nx : static_cast<size_t>(nx) * ny;  // one step along it
  const size_t row_length = stride;                // samples convolved together per step
  const size_t slab_size = static_cast<size_t>(n) * stride;
  std::vector<double> sum(row_length);
  for (int slab = 0; slab < m; ++slab) {
    const size_t base = slab * slab_size;
    for (int i = 0; i < n; ++i) {
      std::fill(sum.begin(), sum.end(), 0.0);
      const int lo = std::max(0, i - radius), hi = std::min(n - 1, i + radius);
      for (int t = lo; t <= hi; ++t) {
        const double w = kernel[t - i + radius];
        const float* in = &input[base + t * stride];
        for (size_t x = 0; x < row_length; ++x) sum[x] += w * in[x];
      }
      float* out = &output[base + i * stride];
      for (size_t x = 0; x < row_length; ++x) out[x] = static_cast<float>(sum[x]);
    }
  }
}

}  // namespace

void IsosurfaceOptions::Check() const {
  if (!std::isfinite(iso_value) || iso_value < 0.0)
    ThrowError("IsosurfaceOptions", "iso_value",
               "expected a finite level ≥ 0 (the zero padding must be outside), got " +
                   std::to_string(iso_value));
  if (!std::isfinite(smoothing_sigma_voxels) || smoothing_sigma_voxels < 0.0)
    ThrowError("IsosurfaceOptions", "smoothing_sigma_voxels",
               "expected a finite standard deviation ≥ 0 voxels, got " +
                   std::to_string(smoothing_sigma_voxels));
  if (padding_voxels < 1 || padding_voxels > 64)
    ThrowError("IsosurfaceOptions", "padding_voxels",
               "expected 1..64 voxels, got " + std::to_string(padding_voxels));
  if (!std::isfinite(facet_angle_degrees) || facet_angle_degrees <= 0.0 ||
      facet_angle_degrees > 30.0)
    ThrowError("IsosurfaceOptions", "facet_angle_degrees",
               "expected an angle in (0, 30] degrees (Mesh_3 terminates only up to 30), got " +
                   std::to_string(facet_angle_degrees));
  CheckFinitePositive(facet_size_voxels, "facet_size_voxels", "size in voxels");
  CheckFinitePositive(facet_distance_voxels, "facet_distance_voxels", "distance in voxels");
  if (max_vertex_count < 0)
    ThrowError("IsosurfaceOptions", "max_vertex_count",
               "expected ≥ 0 (0 = no limit), got " + std::to_string(max_vertex_count));
}

void CheckScalarVolume(const ScalarVolume& volume, const std::string& source) {
  if (volume.nx < 2 || volume.ny < 2 || volume.nz < 2)
    ThrowError(source, "size",
               "expected at least 2 samples per axis, got " + std::to_string(volume.nx) + "×" +
                   std::to_string(volume.ny) + "×" + std::to_string(volume.nz));
  const size_t expected = static_cast<size_t>(volume.nx) * volume.ny * volume.nz;
  if (volume.values.size() != expected)
    ThrowError(source, "values",
               "expected nx·ny·nz = " + std::to_string(expected) + " samples, got " +
                   std::to_string(volume.values.size()));
  if (!volume.origin.allFinite())
    ThrowError(source, "origin", "expected finite coordinates");
  if (!std::isfinite(volume.spacing) || volume.spacing <= 0.0)
    ThrowError(source, "spacing",
               "expected a finite voxel size > 0, got " + std::to_string(volume.spacing));
  for (size_t s = 0; s < volume.values.size(); ++s) {
    if (!std::isfinite(volume.values[s])) {
      const int i = static_cast<int>(s % volume.nx);
      const int j = static_cast<int>((s / volume.nx) % volume.ny);
      const int k = static_cast<int>(s / (static_cast<size_t>(volume.nx) * volume.ny));
      ThrowError(source,
                 "value at voxel (" + std::to_string(i) + ", " + std::to_string(j) + ", " +
                     std::to_string(k) + ")",
                 "expected a finite number, got " + std::to_string(volume.values[s]));
    }
  }
}

ScalarVolume PadAndSmoothVolume(const ScalarVolume& volume, int padding, double sigma_voxels) {
  SUBFLOW_CHECK(padding >= 0, "padding must be ≥ 0");
  ScalarVolume padded(volume.origin - padding * volume.spacing * Eigen::Vector3d::Ones(),
                      volume.spacing, volume.nx + 2 * padding, volume.ny + 2 * padding,
                      volume.nz + 2 * padding, 0.0f);
  for (int k = 0; k < volume.nz; ++k)
    for (int j = 0; j < volume.ny; ++j)
      std::copy_n(&volume.values[volume.Index(0, j, k)], volume.nx,
                  &padded.values[padded.Index(padding, j + padding, k + padding)]);
  if (sigma_voxels > 0.0) {
    const std::vector<double> kernel = GaussianKernel(sigma_voxels);
    for (int axis = 0; axis < 3; ++axis) ConvolveAxis(&padded, axis, kernel);
  }
  return padded;
}

std::vector<IsosurfaceSeed> FindIsosurfaceSeeds(const ScalarVolume& volume, double iso_value,
                                                int* inside_component_count,
                                                int* outside_component_count) {
  // Components are found on runs (maximal x-intervals of one side in one row) with a
  // union-find: two runs of one side touch when they overlap in x in rows (j−1, k) or
  // (j, k−1). This is O(runs), far cheaper than visiting every sample's neighbours.
  struct Run {
    int i0, i1, j, k;  // samples i0..i1 of row (j, k)
    bool inside;
  };
  const int nx = volume.nx, ny = volume.ny, nz = volume.nz;
  std::vector<Run> runs;
  std::vector<size_t> row_begin(static_cast<size_t>(ny) * nz + 1, 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const float* row = &volume.values[volume.Index(0, j, k)];
      for (int i = 0; i < nx;) {
        const bool inside = row[i] > iso_value;
        int end = i;
        while (end + 1 < nx && (row[end + 1] > iso_value) == inside) ++end;
        runs.push_back({i, end, j, k, inside});
        i = end + 1;
      }
      row_begin[static_cast<size_t>(k) * ny + j + 1] = runs.size();
    }
  std::vector<size_t> parent(runs.size());
  for (size_t r = 0; r < runs.size(); ++r) parent[r] = r;
  const auto find = [&](size_t r) {
    while (parent[r] != r) r = parent[r] = parent[parent[r]];
    return r;
  };
  // Union with the touching runs of the previous row `other` (both lists sorted by i0).
  const auto link_rows = [&](size_t row, size_t other) {
    size_t b = row_begin[other];
    for (size_t a = row_begin[row]; a < row_begin[row + 1]; ++a) {
      while (b < row_begin[other + 1] && runs[b].i1 < runs[a].i0) ++b;
      for (size_t c = b; c < row_begin[other + 1] && runs[c].i0 <= runs[a].i1; ++c)
        if (runs[c].inside == runs[a].inside) {
          const size_t root_a = find(a), root_c = find(c);
          // The smaller index stays root: components are numbered in scan order.
          if (root_a != root_c) parent[std::max(root_a, root_c)] = std::min(root_a, root_c);
        }
    }
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      const size_t row = static_cast<size_t>(k) * ny + j;
      if (j > 0) link_rows(row, row - 1);
      if (k > 0) link_rows(row, row - ny);
    }

  // Per component and direction u of the 26 in {−1, 0, 1}³ \ {0}: its sample furthest
  // along u (u·(i, j, k) largest, first found on ties). That sample's neighbour along the
  // first axis a with u_a ≠ 0 is on the other side (else it would belong to the component
  // and lie further along u), unless it is off the grid (then no seed for u).
  std::vector<Eigen::Vector3i> directions;
  for (int z = -1; z <= 1; ++z)
    for (int y = -1; y <= 1; ++y)
      for (int x = -1; x <= 1; ++x)
        if (x != 0 || y != 0 || z != 0) directions.emplace_back(x, y, z);
  const int direction_count = static_cast<int>(directions.size());
  struct Extremes {
    bool inside;
    std::vector<int> extent;
    std::vector<Eigen::Vector3i> sample;
  };
  std::vector<int> component_of_root(runs.size(), -1);
  std::vector<Extremes> components;
  int inside_components = 0;
  for (size_t r = 0; r < runs.size(); ++r) {
    const size_t root = find(r);
    if (component_of_root[root] < 0) {
      component_of_root[root] = static_cast<int>(components.size());
      components.push_back({runs[r].inside,
                            std::vector<int>(direction_count, std::numeric_limits<int>::min()),
                            std::vector<Eigen::Vector3i>(direction_count)});
      inside_components += runs[r].inside ? 1 : 0;
    }
    Extremes& e = components[component_of_root[root]];
    const Run& run = runs[r];
    for (int d = 0; d < direction_count; ++d) {
      const Eigen::Vector3i& u = directions[d];
      const Eigen::Vector3i best_in_run(u.x() > 0 ? run.i1 : run.i0, run.j, run.k);
      const int extent = u.dot(best_in_run);
      if (extent > e.extent[d]) {
        e.extent[d] = extent;
        e.sample[d] = best_in_run;
      }
    }
  }
  std::vector<IsosurfaceSeed> seeds;
  for (size_t c = 0; c < components.size(); ++c) {
    const Extremes& e = components[c];
    for (int d = 0; d < direction_count; ++d) {
      const Eigen::Vector3i& u = directions[d];
      const int axis = u.x() != 0 ? 0 : u.y() != 0 ? 1 : 2;
      Eigen::Vector3i neighbour = e.sample[d];
      neighbour[axis] += u[axis];
      if (!volume.InRange(neighbour.x(), neighbour.y(), neighbour.z())) continue;
      const Eigen::Vector3d here =
          volume.VoxelCenter(e.sample[d].x(), e.sample[d].y(), e.sample[d].z());
      const Eigen::Vector3d there =
          volume.VoxelCenter(neighbour.x(), neighbour.y(), neighbour.z());
      const int id = static_cast<int>(c);
      seeds.push_back(e.inside ? IsosurfaceSeed{id, here, there}
                               : IsosurfaceSeed{id, there, here});
    }
  }
  if (inside_component_count != nullptr) *inside_component_count = inside_components;
  if (outside_component_count != nullptr)
    *outside_component_count = static_cast<int>(components.size()) - inside_components;
  return seeds;
}

}  // namespace subflow::geometry
