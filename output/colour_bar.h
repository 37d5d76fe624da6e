// The colour bar drawn beside a picture coloured by a ColourScale: a margin on the right
// with a vertical bar (bottom = scale.min, top = scale.max), ticks labelled in display
// units at min, middle and max, and the label with its units.
#pragma once

#include <opencv2/core.hpp>

#include "output/colour_scale.h"

namespace subflow::output {

// Where the bar is in the returned picture (pixel rows top..bottom inclusive,
// columns left..right inclusive): row `top` shows scale.max, row `bottom` scale.min.
struct ColourBarBox {
  int left = 0, right = 0, top = 0, bottom = 0;
};

// `picture` (CV_8UC3) widened by a margin holding the bar; *box (optional) receives its place.
cv::Mat WithColourBar(const cv::Mat& picture, const ColourScale& scale, ColourBarBox* box = nullptr);

}  // namespace subflow::output
