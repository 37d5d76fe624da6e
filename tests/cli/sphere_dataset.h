// The small dataset the command tests run on when any object will do: a sphere seen by a
// ring of 5 cameras at 96×72 pixels, 3 frames (~25³ voxels: seconds), with backgrounds.
#pragma once

#include <filesystem>

#include "tests/test_support.h"
#include "vision/synthetic_render.h"

namespace subflow::test {

// Writes the sphere dataset to `path` (replaced if it exists) and returns it.
inline std::filesystem::path WriteSphereDataset(const std::filesystem::path& path) {
  std::filesystem::remove_all(path);
  vision::SynthOptions options;
  options.scene.scene = "sphere";
  options.scene.frame_count = 3;
  options.scene.subdivisions = 4;
  options.rig.camera_count = 5;
  options.rig.width = 96;
  options.rig.height = 72;
  vision::WriteSyntheticDataset(path.string(), options);
  return path;
}

}  // namespace subflow::test
