// The colour scale of every picture, glTF colour and viewer of subflow: viridis
// (perceptually uniform, readable in gray and by colour-blind readers; the 256 sRGB
// entries of OpenCV's COLORMAP_VIRIDIS) over a value range [min, max], values outside
// clamped to the ends. Display units: value × display_factor, e.g. metres shown as mm.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace subflow::output {

struct ColourScale {
  double min = 0.0, max = 1.0;   // world units (per frame for flows)
  double display_factor = 1.0;   // displayed number = value × display_factor
  std::string label;             // what is shown, e.g. "scene flow |v|"
  std::string units;             // display units, e.g. "mm/frame"

  // Position of `value` on the scale in [0, 1] (0 when max ≤ min).
  double Fraction(double value) const;
  // sRGB colour in [0, 1] of `value`, linearly interpolated between table entries.
  Eigen::Vector3f Srgb(double value) const;
  // The 256 sRGB entries, index 0 = min.
  static const std::array<std::array<std::uint8_t, 3>, 256>& Table();
};

// sRGB component in [0, 1] → linear (IEC 61966-2-1), as glTF's COLOR_0 expects.
float SrgbToLinear(float srgb);

}  // namespace subflow::output
