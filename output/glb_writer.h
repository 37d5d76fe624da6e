// The result as one glTF 2.0 binary (.glb), written with tinygltf:
//   mesh       the first frame: POSITION (float32), NORMAL (optional, area-weighted
//              vertex normals), COLOR_0 (optional, the flow magnitude of the frame on the
//              viridis ColourScale, linear RGB as glTF wants), indices (uint16 when
//              #V ≤ 65 535, else uint32); faces as in the result (counter-clockwise).
//   targets    one morph target per later frame f = 1..N−1: POSITION (and NORMAL,
//              COLOR_0) deltas from the first frame, float32, so base + delta is frame f
//              to float precision. A target whose deltas are zero on most vertices is
//              stored sparse (indices + values of the vertices that moved) when that is
//              smaller than dense. mesh.extras.targetNames are the frame names.
//   animation  "subflow": input = frame times (f − first) / fps seconds, output = the N
//              weight vectors (one-hot: weight 1 on frame f's target, all 0 at frame 0),
//              LINEAR, so positions between frames interpolate linearly between them.
//   node       carries the result's world coordinates unchanged in its mesh and a
//              rotation that takes the world's `up` to glTF's +Y, so glTF viewers show
//              the object upright and Blender's importer (Y-up → Z-up) gives back the
//              world coordinates when up = +Z.
// Memory: the whole file is assembled in memory (glTF binary chunks carry their length
// up front); the size is ≈ N · #V · 12 bytes per morphed attribute, refused above 4 GiB.
#pragma once

#include <cstddef>
#include <string>

#include <Eigen/Core>

#include "core/progress.h"
#include "output/colour_scale.h"
#include "output/flow_magnitude.h"
#include "output/result_reader.h"

namespace subflow::output {

struct GlbOptions {
  double fps = 30.0;                          // frames per second of the animation (> 0)
  bool normals = true;                        // NORMAL and its morph deltas (smooth shading)
  bool colours = false;                       // COLOR_0 by flow magnitude, per frame
  FlowKind colour_flow = FlowKind::kTotal;    // which flow colours show
  ColourScale colour_scale;                   // range used for COLOR_0 (see SequenceFlowRange)
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // world up direction (taken to glTF +Y)
  bool sparse = true;                         // allow sparse morph targets

  void Check() const;  // throws subflow::Error on nonsense (fps ≤ 0, up zero)
};

struct GlbSummary {
  std::size_t bytes = 0;        // size of the .glb
  int morph_targets = 0;
  int sparse_targets = 0;       // of which stored sparse
};

GlbSummary WriteGlb(const ResultReader& result, const std::string& path, const GlbOptions& options,
                    Progress* progress = nullptr);

}  // namespace subflow::output
