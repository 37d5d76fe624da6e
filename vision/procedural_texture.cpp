#include "vision/procedural_texture.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace subflow::vision {
namespace {

double UnitFloat(std::uint32_t h) { return (h >> 8) * (1.0 / 16777216.0); }  // [0, 1)

double Fade(double t) { return t * t * (3.0 - 2.0 * t); }

}  // namespace

std::uint32_t HashLattice(int x, int y, int z, std::uint32_t seed) {
  // Murmur3-style finalizer over a linear mix of the coordinates.
  std::uint32_t h = seed * 0x9E3779B1u;
  h ^= static_cast<std::uint32_t>(x) * 0x85EBCA77u;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<std::uint32_t>(y) * 0xC2B2AE3Du;
  h = (h << 13) | (h >> 19);
  h ^= static_cast<std::uint32_t>(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return h;
}

double ValueNoise(const Eigen::Vector3d& x, std::uint32_t seed) {
  const double fx = std::floor(x.x()), fy = std::floor(x.y()), fz = std::floor(x.z());
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy), iz = static_cast<int>(fz);
  const double tx = Fade(x.x() - fx), ty = Fade(x.y() - fy), tz = Fade(x.z() - fz);
  double corner[2][2][2];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 2; ++c) corner[a][b][c] = UnitFloat(HashLattice(ix + a, iy + b, iz + c, seed));
  auto lerp = [](double p, double q, double t) { return p + (q - p) * t; };
  const double x00 = lerp(corner[0][0][0], corner[1][0][0], tx);
  const double x10 = lerp(corner[0][1][0], corner[1][1][0], tx);
  const double x01 = lerp(corner[0][0][1], corner[1][0][1], tx);
  const double x11 = lerp(corner[0][1][1], corner[1][1][1], tx);
  return lerp(lerp(x00, x10, ty), lerp(x01, x11, ty), tz);
}

Eigen::Vector3d ProceduralAlbedo::operator()(const Eigen::Vector3d& rest) const {
  const ProceduralAlbedoOptions& o = options_;
  const Eigen::Vector3d p = rest / o.cell_size;
  const int cx = static_cast<int>(std::floor(p.x()));
  const int cy = static_cast<int>(std::floor(p.y()));
  const int cz = static_cast<int>(std::floor(p.z()));
  const Eigen::Vector3d frac = p - Eigen::Vector3d(cx, cy, cz);
  // Neighbour cells in order of their distance from p's cell (own cell, faces, edges,
  // corners); a cell whose nearest possible site is no closer than F2 cannot change F1
  // or F2 and is skipped (same result as visiting all 27, fewer hashes).
  static const auto kOffsets = [] {
    std::array<Eigen::Vector3i, 27> offsets;
    int n = 0;
    for (int nonzero = 0; nonzero <= 3; ++nonzero)
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if ((dx != 0) + (dy != 0) + (dz != 0) == nonzero) offsets[n++] = Eigen::Vector3i(dx, dy, dz);
    return offsets;
  }();
  double f1 = 1e30, f2 = 1e30;
  std::uint32_t nearest = 0;
  for (const Eigen::Vector3i& d : kOffsets) {
    double gap2 = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double gap = d[k] < 0 ? frac[k] : (d[k] > 0 ? 1.0 - frac[k] : 0.0);
      gap2 += gap * gap;
    }
    if (gap2 >= f2) continue;
    const std::uint32_t h = HashLattice(cx + d.x(), cy + d.y(), cz + d.z(), o.seed);
    const Eigen::Vector3d site(cx + d.x() + UnitFloat(h), cy + d.y() + UnitFloat(h * 747796405u + 1u),
                               cz + d.z() + UnitFloat(h * 2891336453u + 7u));
    const double d2 = (site - p).squaredNorm();
    if (d2 < f1) {
      f2 = f1;
      f1 = d2;
      nearest = h;
    } else if (d2 < f2) {
      f2 = d2;
    }
  }
  // Cell colour: a brightness and a mild tint from the nearest site's hash.
  const double brightness =
      o.min_brightness + (o.max_brightness - o.min_brightness) * UnitFloat(nearest * 1103515245u + 12345u);
  const Eigen::Vector3d random_colour(UnitFloat(nearest * 2654435761u + 3u), UnitFloat(nearest * 40503u + 5u),
                                      UnitFloat(nearest * 2246822519u + 11u));
  Eigen::Vector3d colour = brightness * ((1.0 - o.tint) * Eigen::Vector3d::Ones() +
                                         o.tint * 2.0 * random_colour);
  // Border: F2 − F1 in metres (distances in cell units × cell_size).
  const double gap = (std::sqrt(f2) - std::sqrt(f1)) * o.cell_size;
  const double border = std::clamp(gap / o.border_width, 0.0, 1.0);
  colour *= 1.0 - o.border_darkness * (1.0 - Fade(border));
  const double blotch = ValueNoise(rest / o.blotch_size, o.seed ^ 0x5bd1e995u);
  colour *= 1.0 + o.blotch_contrast * (2.0 * blotch - 1.0);
  return colour.cwiseMax(0.0).cwiseMin(1.0);
}

}  // namespace subflow::vision
