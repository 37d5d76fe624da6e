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
};

struct ViewerSummary {
  std::size_t bytes = 0;
  std::vector<std::string> colourings;
};

// Throws subflow::Error when this build has no viewer (ViewerAvailable() false).
ViewerSummary WriteViewer(const ResultReader& result, const vision::Dataset* dataset, const ResultMetadata& metadata,
                          const std::string& path, const ViewerOptions& options, Progress* progress = nullptr);

}  // namespace subflow::output
