// Point caches of a result for Blender's Mesh Cache modifier (and 3ds Max, Maya, Houdini
// importers of the same formats): the vertex positions of every frame, in the result's
// vertex order, beside a base mesh with that order (WriteBaseObj). Both writers stream
// the result frame by frame (memory of one frame, whatever the sequence length) into a
// temporary file renamed when complete.
//
// PC2 (little-endian, as Blender's MOD_meshcache_pc2 reads it):
//   char[12] "POINTCACHE2\0"; int32 version = 1; int32 vertex count;
//   float32 start frame; float32 sampling (frames between samples) = 1;
//   int32 frame count; then per frame, per vertex float32 x y z.
// MDD (big-endian, as MOD_meshcache_mdd reads it):
//   int32 frame count; int32 vertex count; float32 time of every frame (seconds,
//   (frame − first frame) / fps); then per frame, per vertex float32 x y z.
// Coordinates are the result's world coordinates as they are (no axis change): import
// with the modifier's forward/up axes at +Y / +Z (Blender's defaults, identity).
#pragma once

#include <string>

#include "core/progress.h"
#include "output/result_reader.h"

namespace subflow::output {

// Writes the PC2 of `result` to `path`; `start_frame` is recorded in the header (the
// result's first frame index is the natural choice).
void WritePc2(const ResultReader& result, const std::string& path, float start_frame,
              Progress* progress = nullptr);

// Writes the MDD of `result` to `path`, frame times at `fps` (> 0) frames per second.
void WriteMdd(const ResultReader& result, const std::string& path, double fps,
              Progress* progress = nullptr);

// Writes the first frame as OBJ ("v" with 17 significant digits, one "f" per face, same
// vertex order, no splitting): the mesh the point caches animate.
void WriteBaseObj(const ResultReader& result, const std::string& path);

}  // namespace subflow::output
