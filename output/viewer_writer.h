// `subflow view`: one self-contained HTML page that plays a result in a browser — no
// network, no install: three.js and the viewer script are embedded in the binary at build
// time (output/viewer_assets.h), the result's data inline as JSON with base64 arrays:
//   positions     float32, frames × #V × 3 (world units; the page computes normals)
//   indices       uint32, #F × 3
//   colourings    "flow", "nonrigid" (when the result has it): float32 magnitudes per
//                 frame and vertex on the sequence's range (ColourScale, viridis);
//                 "texture" (with a dataset): uint8 sRGB per frame and vertex from the
//                 cameras that see the vertex best (output/camera_texture.h)
//   fps, up       playback rate; the world's up direction (dataset cameras' up, else +Z)
// Size ≈ frames · #V · (16 + 4 per flow + 3 for texture) · 4/3 bytes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/progress.h"
#include "output/result_metadata.h"
#include "output/result_reader.h"
#include "vision/dataset.h"

namespace subflow::output {

struct ViewerOptions {
  bool texture = true;        // the texture colouring (needs the dataset's images)
  std::string title = "subflow result";
  // Every `stride`-th frame goes into the page (playback keeps real time: fps / stride).
  // 0: automatic, the smallest stride whose page stays under `max_bytes`. The cap exists
  // because the page's data is one JavaScript string: V8 refuses strings over 2^29 − 24
  // characters (~512 MiB), and a page of several hundred MB takes minutes to open.
  int stride = 0;
  std::size_t max_bytes = std::size_t(256) << 20;
};

struct ViewerSummary {
  std::size_t bytes = 0;
  std::vector<std::string> colourings;
  int stride = 1;            // the stride used
  int frames_in_page = 0;    // frames written into the page
  std::size_t estimated_bytes_all_frames = 0;  // the page's size estimate with every frame
};

// The page's size estimate for `frames` frames of `vertex_count` vertices with
// `magnitude_channels` flow colourings and, if `texture`, the texture colouring; and the
// stride that options.stride (or the automatic choice) gives for a result of that shape.
std::size_t EstimatedViewerBytes(std::size_t vertex_count, std::size_t frames, std::size_t magnitude_channels,
                                 bool texture);
int ViewerStride(const ViewerOptions& options, std::size_t vertex_count, std::size_t frames,
                 std::size_t magnitude_channels, bool texture);

// Throws subflow::Error when this build has no viewer (ViewerAvailable() false).
ViewerSummary WriteViewer(const ResultReader& result, const vision::Dataset* dataset, const ResultMetadata& metadata,
                          const std::string& path, const ViewerOptions& options, Progress* progress = nullptr);

}  // namespace subflow::output
