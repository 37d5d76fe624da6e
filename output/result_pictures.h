// `subflow render`: pictures of a result, PNG (and optionally MP4), through the z-buffer.
// In <out>/ (frame = six-digit frame name, camera = the dataset's camera name):
//   flow/<camera>/<frame>.png          surface coloured by scene-flow magnitude, shaded,
//   nonrigid/<camera>/<frame>.png      ... by non-rigid flow (when the result has it),
//                                      from the dataset's cameras, with the colour bar
//   turntable/<kind>_<frame>_view<k>.png  the same from `turntable.count` new views around
//                                      the object (up = the dataset cameras' up, else +Z)
//   textured/<frame>_view<k>.png       new views textured from the input cameras that see
//                                      each point best (output/camera_texture.h)
//   overlay/<camera>/<frame>.png       outline + flow shading over the undistorted input
//   contact_sheet/<frame>.png          the overlays of every camera in one picture
//   mp4/<camera>.mp4                   overlays of every frame (with mp4 = true)
// With colour_by = a vertex property, that property replaces the flows in every picture.
// Colour scales run over the whole sequence's magnitudes (SequenceFlowRange), so
// pictures of different frames compare. Without a dataset only the turntable is drawn.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/progress.h"
#include "output/colour_bar.h"
#include "output/overlay.h"
#include "output/result_metadata.h"
#include "output/result_reader.h"
#include "output/surface_shading.h"
#include "output/view_cameras.h"
#include "vision/dataset.h"

namespace subflow::output {

struct RenderOptions {
  std::vector<int> frames;       // frame numbers to picture; empty: first, middle and last
  int turntable_frame = -1;      // frame of the turntable and textured views; −1: the middle one
  TurntableOptions turntable;    // new views (count 0: none)
  bool textured = true;          // textured new views (needs the dataset's images)
  bool overlays = true;          // overlays and contact sheets (needs the dataset's images)
  bool mp4 = false;              // an MP4 of the overlays per camera, every frame, at the result's fps
  ShadingOptions shading;
  OverlayOptions overlay;
  // A scalar vertex property to colour by instead of the flows (e.g. "distance" of
  // `subflow eval --error-maps`); pictures are then named by it (<colour_by>/<camera>/...).
  std::string colour_by;
  // The colour range of colour_by (world units as stored): {min, max}; empty = the
  // sequence's smallest and largest value.
  std::vector<double> colour_range;
};

// One picture written, for report.json and tests.
struct Picture {
  std::string path;      // relative to <out>
  std::string kind;      // flow, nonrigid, textured, overlay, contact_sheet, mp4
  int frame = 0;
  std::string view;      // camera or view name
  int surface_pixels = 0;            // pixels the surface covers
  int pixels = 0;                    // of the surface's image (without the colour bar)
  ColourBarBox bar;                  // when the picture has a colour bar
  bool has_bar = false;
};

struct RenderSummary {
  std::vector<Picture> pictures;
  std::map<std::string, ColourScale> scales;  // "flow", "nonrigid"
  nlohmann::json Json() const;
};

// `dataset` may be null (no input cameras or images). Writes into the existing `out`.
RenderSummary RenderResultPictures(const ResultReader& result, const vision::Dataset* dataset,
                                   const ResultMetadata& metadata, const std::string& out,
                                   const RenderOptions& options, Progress* progress = nullptr);

}  // namespace subflow::output
