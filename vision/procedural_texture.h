// Procedural albedo bound to material points: a function of a point's REST position
// (world units), so that the texture moves with the surface as it deforms. Used by the
// synthetic renderer; deterministic for a given seed, thread-safe (pure functions).
//
// albedo(x) = cell_colour(x) · blotch(x) · border(x), RGB in [0, 1] (linear):
//   cells:   3D Voronoi cells of jittered points, one per cube of side cell_size; each
//            cell has its own brightness and a mild tint;
//   border:  dark lines where the distances to the nearest and second-nearest cell
//            points differ by less than border_width (F2 − F1 < border_width);
//   blotch:  multiplicative 3D value noise of period blotch_size, contrast ±blotch_contrast.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace subflow::vision {

struct ProceduralAlbedoOptions {
  double cell_size = 0.008;        // metres between Voronoi cell points (≈ 5.6 px at 0.6 m, f = 420)
  double border_width = 0.0012;    // metres, F2 − F1 below which the cell border is dark
  double border_darkness = 0.75;   // fraction of the albedo removed on a border
  double blotch_size = 0.004;      // metres, period of the value-noise blotches
  double blotch_contrast = 0.3;    // blotches scale the albedo by 1 ± this
  double min_brightness = 0.2;     // cell brightness range (linear albedo)
  double max_brightness = 0.85;
  double tint = 0.25;              // 0 = gray cells, 1 = fully random colours
  std::uint32_t seed = 1;
};

class ProceduralAlbedo {
 public:
  explicit ProceduralAlbedo(const ProceduralAlbedoOptions& options = {}) : options_(options) {}
  // Linear RGB albedo at rest position `rest`.
  Eigen::Vector3d operator()(const Eigen::Vector3d& rest) const;

 private:
  ProceduralAlbedoOptions options_;
};

// Smooth 3D value noise in [0, 1] with unit lattice spacing (trilinear interpolation of
// hashed lattice values with a smoothstep fade).
double ValueNoise(const Eigen::Vector3d& x, std::uint32_t seed);
// A well-mixed 32-bit hash of an integer lattice point and a seed.
std::uint32_t HashLattice(int x, int y, int z, std::uint32_t seed);

}  // namespace subflow::vision
