// A still set photographed against a plain backdrop — black velvet, a studio's seamless
// paper, a green screen, the dark room of a turntable rig (Middlebury's dino and temple) —
// has its background image in plain sight: one colour. Photo-consistency
// (vision/still_evidence.h) needs texture on the object and behind it; on a plain backdrop
// there is none behind it, and a matte object of little texture gives few trusted depths
// (the dino: 378,000 voxels that nothing freed, a hull filling the box). The backdrop's
// colour, compared with every pixel as a background image is (vision/silhouettes.h:
// SilhouetteFromBackground), separates them instead.
//
// Per camera, the backdrop is read on the image's border band (border_fraction of the
// shorter side), where it shows around the object. The band is a guess — an object or a
// prop may reach the frame's edge — so everything read from it is robust:
//   colour  c = the per-channel median of the band's pixels,
//   spread  s = the spread_quantile-quantile of max_channel |I(p) − c| over them.
// The backdrop is plain when s ≤ max_spread: an object or a prop covering less than
// 1 − spread_quantile of the band moves both figures only within the backdrop's own
// distribution (the spread becomes a higher percentile of its noise), and a textured room (the
// synthetic scenes' walls and floors: s of 0.17 and more) or a cluttered lab is not plain.
// Not the pixels outside the projected working volume, though they surely show no object:
// what lies there (the Middlebury temple's lit cloth below a tight box) is background
// whatever its look, and would make a plain backdrop look textured. A backdrop with a
// lighting gradient beyond max_spread is not plain either; the set then keeps the
// photo-consistency. Unlike the photo-consistency, nothing here removes a support plane:
// a table top or turntable that differs from the backdrop is part of the silhouettes
// wherever the working volume holds it.
#pragma once

#include <opencv2/core.hpp>

namespace subflow::vision {

struct PlainBackdropOptions {
  bool enabled = true;
  double border_fraction = 0.02;  // border band, fraction of the image's shorter side (≥ 2 px)
  double spread_quantile = 0.6;
  double max_spread = 0.03;       // encoded units in [0, 1] (8/255)

  void Check() const;  // throws subflow::Error naming the field
};

struct PlainBackdrop {
  bool plain = false;
  cv::Scalar colour;    // per channel, in [0, 1] (the image's channel order: B, G, R or gray)
  int channels = 0;     // of `colour` (alpha dropped)
  double spread = 0;    // the spread_quantile of the distances to `colour`
  int sure_pixels = 0;  // pixels the figures were read from
};

// CV_8UC1 of `size`: 255 on the border band, 0 inside it.
cv::Mat BorderBand(cv::Size size, const PlainBackdropOptions& options = {});

// The backdrop's figures read on `image` (CV_8U, CV_16U or CV_32F in [0, 1]; 1, 3 or 4
// channels, alpha ignored) at the pixels of `sure` (CV_8UC1 of its size, e.g. BorderBand).
// Not plain when `sure` has no pixel.
PlainBackdrop MeasureBackdrop(const cv::Mat& image, const cv::Mat& sure, const PlainBackdropOptions& options = {});

// The backdrop as a background image: `colour` everywhere, CV_32F with the backdrop's
// channels (those MeasureBackdrop read on `image`), `image`'s size.
cv::Mat BackdropImage(const cv::Mat& image, const PlainBackdrop& backdrop);

}  // namespace subflow::vision
