#include "vision/voxel_morphology.h"

#include <algorithm>
#include <vector>

#include <Eigen/Core>
#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::vision {
namespace {

using geometry::ScalarVolume;

// One separable pass of a box dilation (or erosion) of radius r along `axis`.
// The volume is seen as [outer][n][inner] with n the axis length: x → inner = 1;
// y → inner = nx; z → inner = nx·ny. A running count of "active" voxels (occupied for a
// dilation, empty for an erosion) over the window [k − r, k + r] gives each output in O(1);
// outside the volume nothing is active (empty for dilation, occupied for erosion).
void BoxPass(const BinaryVolume& in, BinaryVolume* out, int axis, int r, bool erode) {
  const size_t n = axis == 0 ? in.nx : axis == 1 ? in.ny : in.nz;
  const size_t inner = axis == 0 ? 1 : axis == 1 ? in.nx : static_cast<size_t>(in.nx) * in.ny;
  const size_t outer = in.size() / (n * inner);
  const uint8_t active_value = erode ? 0 : 1;
  const uint8_t* source = in.values.data();
  uint8_t* target = out->values.data();
  const size_t reach = static_cast<size_t>(r);
  if (inner == 1) {  // along x: each line is contiguous, one running count per line
    tbb::parallel_for(tbb::blocked_range<size_t>(0, outer, 64), [&](const tbb::blocked_range<size_t>& lines) {
      for (size_t o = lines.begin(); o != lines.end(); ++o) {
        const uint8_t* line = source + o * n;
        uint8_t* result = target + o * n;
        int count = 0;
        for (size_t k = 0; k < std::min(reach, n); ++k) count += line[k] == active_value;
        for (size_t k = 0; k < n; ++k) {
          if (k + reach < n) count += line[k + reach] == active_value;
          if (k >= reach + 1) count -= line[k - reach - 1] == active_value;
          result[k] = erode ? (count == 0) : (count > 0);
        }
      }
    });
    return;
  }
  // Along y or z: lines are strided, so count whole rows of `inner` voxels at a time.
  tbb::parallel_for(
      tbb::blocked_range2d<size_t>(size_t(0), outer, size_t(1), size_t(0), inner, size_t(1024)),
      [&](const tbb::blocked_range2d<size_t>& range) {
        const size_t i0 = range.cols().begin(), width = range.cols().end() - i0;
        std::vector<int> count(width);
        for (size_t o = range.rows().begin(); o != range.rows().end(); ++o) {
          const size_t base = o * n * inner + i0;
          std::fill(count.begin(), count.end(), 0);
          auto add = [&](size_t k, int sign) {
            const uint8_t* slice = source + base + k * inner;
            for (size_t i = 0; i < width; ++i) count[i] += sign * (slice[i] == active_value);
          };
          for (size_t k = 0; k < std::min(reach, n); ++k) add(k, +1);
          for (size_t k = 0; k < n; ++k) {
            if (k + reach < n) add(k + reach, +1);
            if (k >= reach + 1) add(k - reach - 1, -1);
            uint8_t* slice = target + base + k * inner;
            for (size_t i = 0; i < width; ++i) slice[i] = erode ? (count[i] == 0) : (count[i] > 0);
          }
        }
      });
}

void Box(BinaryVolume* volume, int radius, bool erode) {
  SUBFLOW_CHECK(radius >= 0, "negative structuring element radius");
  if (radius == 0 || volume->values.empty()) return;
  BinaryVolume scratch(volume->nx, volume->ny, volume->nz);
  BoxPass(*volume, &scratch, 0, radius, erode);
  BoxPass(scratch, volume, 1, radius, erode);
  BoxPass(*volume, &scratch, 2, radius, erode);
  volume->values.swap(scratch.values);
}

// The volume with a one-voxel frame around it, so that neighbours are index offsets
// without bounds checks: padded index of (i, j, k) = (i+1) + px·((j+1) + py·(k+1)).
struct Padded {
  explicit Padded(const BinaryVolume& v) : px(v.nx + 2), py(v.ny + 2), pz(v.nz + 2) {}
  size_t Index(int i, int j, int k) const {
    return static_cast<size_t>(i + 1) + static_cast<size_t>(px) * ((j + 1) + static_cast<size_t>(py) * (k + 1));
  }
  size_t size() const { return static_cast<size_t>(px) * py * pz; }
  std::vector<ptrdiff_t> Neighbours(int connectivity) const {
    SUBFLOW_CHECK(connectivity == 6 || connectivity == 26, "connectivity must be 6 or 26");
    std::vector<ptrdiff_t> offsets;
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int nonzero = (di != 0) + (dj != 0) + (dk != 0);
          if (nonzero == 0 || (connectivity == 6 && nonzero != 1)) continue;
          offsets.push_back(di + static_cast<ptrdiff_t>(px) * (dj + static_cast<ptrdiff_t>(py) * dk));
        }
    return offsets;
  }
  int px, py, pz;
};

// Flood fill over cells whose label is `from`, starting at `seed` (labelled `from`),
// writing `to`; returns the cells reached. Explicit stack; padded cells must never be
// `from`, which keeps the fill inside the volume.
size_t Flood(std::vector<int>* labels, const std::vector<ptrdiff_t>& offsets, size_t seed, int from,
             int to, std::vector<size_t>* stack) {
  stack->clear();
  stack->push_back(seed);
  (*labels)[seed] = to;
  size_t reached = 1;
  int* label = labels->data();
  while (!stack->empty()) {
    const size_t v = stack->back();
    stack->pop_back();
    for (ptrdiff_t offset : offsets) {
      const size_t w = v + offset;
      if (label[w] != from) continue;
      label[w] = to;
      ++reached;
      stack->push_back(w);
    }
  }
  return reached;
}

}  // namespace

BinaryVolume::BinaryVolume(const ScalarVolume& volume)
    : BinaryVolume(volume.nx, volume.ny, volume.nz) {
  SUBFLOW_CHECK(volume.values.size() == values.size(), "ScalarVolume values do not match its dimensions");
  for (size_t v = 0; v < values.size(); ++v) values[v] = volume.values[v] > 0.5f;
}

void BinaryVolume::CopyTo(ScalarVolume* volume) const {
  SUBFLOW_CHECK(volume->nx == nx && volume->ny == ny && volume->nz == nz &&
                    volume->values.size() == values.size(),
                "BinaryVolume::CopyTo: dimensions differ");
  for (size_t v = 0; v < values.size(); ++v) volume->values[v] = values[v] ? 1.0f : 0.0f;
}

size_t BinaryVolume::Count() const {
  size_t count = 0;
  for (uint8_t value : values) count += value != 0;
  return count;
}

void DilateBox(BinaryVolume* volume, int radius) { Box(volume, radius, false); }
void ErodeBox(BinaryVolume* volume, int radius) { Box(volume, radius, true); }
void CloseBox(BinaryVolume* volume, int radius) {
  DilateBox(volume, radius);
  ErodeBox(volume, radius);
}
void OpenBox(BinaryVolume* volume, int radius) {
  ErodeBox(volume, radius);
  DilateBox(volume, radius);
}

ComponentSummary KeepLargeComponents(BinaryVolume* volume, double min_fraction, int connectivity) {
  SUBFLOW_CHECK(min_fraction >= 0 && min_fraction <= 1, "min_fraction must be in [0, 1]");
  const Padded padded(*volume);
  const std::vector<ptrdiff_t> offsets = padded.Neighbours(connectivity);
  // −1: empty or frame; 0: occupied, not yet labelled; ≥ 1: component label.
  std::vector<int> labels(padded.size(), -1);
  for (int k = 0; k < volume->nz; ++k)
    for (int j = 0; j < volume->ny; ++j)
      for (int i = 0; i < volume->nx; ++i)
        if (volume->at(i, j, k)) labels[padded.Index(i, j, k)] = 0;
  std::vector<size_t> sizes{0}, stack;
  for (size_t v = 0; v < labels.size(); ++v)
    if (labels[v] == 0) sizes.push_back(Flood(&labels, offsets, v, 0, static_cast<int>(sizes.size()), &stack));
  ComponentSummary summary;
  summary.found = static_cast<int>(sizes.size()) - 1;
  summary.largest = *std::max_element(sizes.begin(), sizes.end());
  std::vector<uint8_t> keep(sizes.size(), 0);
  for (size_t label = 1; label < sizes.size(); ++label) {
    keep[label] = sizes[label] >= min_fraction * summary.largest;
    if (keep[label]) ++summary.kept;
    else summary.removed_voxels += sizes[label];
  }
  for (int k = 0; k < volume->nz; ++k)
    for (int j = 0; j < volume->ny; ++j)
      for (int i = 0; i < volume->nx; ++i) {
        const int label = labels[padded.Index(i, j, k)];
        volume->at(i, j, k) = label > 0 && keep[label];
      }
  return summary;
}

size_t FillCavities(BinaryVolume* volume, int connectivity) {
  SUBFLOW_CHECK(connectivity == 6 || connectivity == 26, "connectivity must be 6 or 26");
  // Only the bounding box of the occupied voxels grown by one voxel (clipped to the volume)
  // can hold a cavity; its boundary layer is empty (or the volume's border), and every
  // path from inside the box to the volume's border crosses that layer, so flooding from
  // the layer's empty voxels within the box finds exactly the border-connected ones.
  Eigen::Array3i lo(volume->nx, volume->ny, volume->nz), hi(-1, -1, -1);
  for (int k = 0; k < volume->nz; ++k)
    for (int j = 0; j < volume->ny; ++j)
      for (int i = 0; i < volume->nx; ++i)
        if (volume->at(i, j, k)) lo = lo.min(Eigen::Array3i(i, j, k)), hi = hi.max(Eigen::Array3i(i, j, k));
  if ((hi < 0).any()) return 0;  // nothing occupied
  lo = (lo - 1).max(0);
  hi = (hi + 1).min(Eigen::Array3i(volume->nx, volume->ny, volume->nz) - 1);
  const Padded padded(*volume);
  // 0: occupied; 1: empty, not (yet) reached from the border; 2: reached, or outside the
  // box (the frame of the padded array included, so the flood never leaves the array).
  std::vector<int> labels(padded.size(), 2);
  for (int k = lo.z(); k <= hi.z(); ++k)
    for (int j = lo.y(); j <= hi.y(); ++j)
      for (int i = lo.x(); i <= hi.x(); ++i) labels[padded.Index(i, j, k)] = volume->at(i, j, k) ? 0 : 1;
  const std::vector<ptrdiff_t> offsets = padded.Neighbours(connectivity == 26 ? 6 : 26);
  std::vector<size_t> stack;
  for (int k = lo.z(); k <= hi.z(); ++k)
    for (int j = lo.y(); j <= hi.y(); ++j)
      for (int i = lo.x(); i <= hi.x(); ++i) {
        const bool layer = i == lo.x() || j == lo.y() || k == lo.z() || i == hi.x() || j == hi.y() || k == hi.z();
        const size_t v = padded.Index(i, j, k);
        if (layer && labels[v] == 1) Flood(&labels, offsets, v, 1, 2, &stack);
      }
  size_t filled = 0;
  for (int k = lo.z(); k <= hi.z(); ++k)
    for (int j = lo.y(); j <= hi.y(); ++j)
      for (int i = lo.x(); i <= hi.x(); ++i)
        if (labels[padded.Index(i, j, k)] == 1) {
          volume->at(i, j, k) = 1;
          ++filled;
        }
  return filled;
}

// ScalarVolume overloads: convert, apply, write back.
void DilateBox(ScalarVolume* volume, int radius) {
  BinaryVolume binary(*volume);
  DilateBox(&binary, radius);
  binary.CopyTo(volume);
}
void ErodeBox(ScalarVolume* volume, int radius) {
  BinaryVolume binary(*volume);
  ErodeBox(&binary, radius);
  binary.CopyTo(volume);
}
void CloseBox(ScalarVolume* volume, int radius) {
  BinaryVolume binary(*volume);
  CloseBox(&binary, radius);
  binary.CopyTo(volume);
}
void OpenBox(ScalarVolume* volume, int radius) {
  BinaryVolume binary(*volume);
  OpenBox(&binary, radius);
  binary.CopyTo(volume);
}
ComponentSummary KeepLargeComponents(ScalarVolume* volume, double min_fraction, int connectivity) {
  BinaryVolume binary(*volume);
  const ComponentSummary summary = KeepLargeComponents(&binary, min_fraction, connectivity);
  binary.CopyTo(volume);
  return summary;
}
size_t FillCavities(ScalarVolume* volume, int connectivity) {
  BinaryVolume binary(*volume);
  const size_t filled = FillCavities(&binary, connectivity);
  binary.CopyTo(volume);
  return filled;
}

}  // namespace subflow::vision
