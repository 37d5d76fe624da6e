// The viewer's size guard: the automatic stride keeps the page under its cap, an explicit
// stride is kept, and the size estimate grows with every channel the page carries.
#include <gtest/gtest.h>

#include "output/viewer_writer.h"

namespace subflow::output {
namespace {

TEST(ViewerStride, AutomaticStrideKeepsThePageUnderTheCap) {
  ViewerOptions options;
  options.max_bytes = std::size_t(256) << 20;
  // The shared sample: 12,802 vertices × 24 frames, two flow channels and texture: ~9 MB.
  EXPECT_EQ(ViewerStride(options, 12802, 24, 2, true), 1);
  // 100k vertices × 1,000 frames would be ~3 GB: every k-th frame, under the cap.
  const int stride = ViewerStride(options, 100000, 1000, 2, true);
  EXPECT_GT(stride, 1);
  const std::size_t frames_in_page = (1000 + stride - 1) / stride;
  EXPECT_LE(EstimatedViewerBytes(100000, frames_in_page, 2, true), options.max_bytes);
  // One frame less of stride would not fit.
  const std::size_t denser = (1000 + stride - 2) / (stride - 1);
  EXPECT_GT(EstimatedViewerBytes(100000, denser, 2, true), options.max_bytes);
}

TEST(ViewerStride, ExplicitStrideIsKept) {
  ViewerOptions options;
  options.stride = 3;
  EXPECT_EQ(ViewerStride(options, 100000, 1000, 2, true), 3);
  EXPECT_EQ(ViewerStride(options, 10, 2, 0, false), 3);
}

TEST(ViewerStride, EstimateCountsEveryChannel) {
  EXPECT_EQ(EstimatedViewerBytes(300, 10, 0, false), 300u * 10u * 12u / 3u * 4u);
  EXPECT_GT(EstimatedViewerBytes(300, 10, 1, false), EstimatedViewerBytes(300, 10, 0, false));
  EXPECT_GT(EstimatedViewerBytes(300, 10, 1, true), EstimatedViewerBytes(300, 10, 1, false));
}

}  // namespace
}  // namespace subflow::output
