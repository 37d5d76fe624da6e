#include "output/result_files.h"

#include <filesystem>

#include "geometry/mesh_io.h"
#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

void WriteHullFiles(const std::string& out, const solver::ShapeInitResult& result) {
  const fs::path root(out);
  fs::create_directories(root / "hull");
  geometry::WriteMesh((root / "base_mesh.ply").string(), result.base_mesh);
  for (const solver::FrameShapeInit& frame : result.frames)
    geometry::WriteMesh((root / "hull" / (vision::FrameName(frame.frame) + ".ply")).string(), frame.hull);
}

void WriteControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy,
                       int first_frame, const std::vector<std::vector<geometry::Positions>>& levels) {
  for (std::size_t i = 0; i < levels.size(); ++i) {
    const fs::path directory =
        fs::path(out) / "control" / vision::FrameName(first_frame + static_cast<int>(i));
    fs::create_directories(directory);
    for (std::size_t level = 0; level < levels[i].size(); ++level)
      geometry::WriteMesh((directory / ("level_" + std::to_string(level) + ".ply")).string(),
                          geometry::TriangleMesh{levels[i][level], hierarchy.LevelFaces(static_cast<int>(level))});
  }
}

void WriteObjSequence(const std::string& out, int first_frame, const geometry::Faces& faces,
                      const std::vector<geometry::Positions>& positions) {
  const fs::path directory = fs::path(out) / "obj";
  fs::create_directories(directory);
  for (std::size_t i = 0; i < positions.size(); ++i)
    geometry::WriteMesh((directory / (vision::FrameName(first_frame + static_cast<int>(i)) + ".obj")).string(),
                        geometry::TriangleMesh{positions[i], faces});
}

}  // namespace subflow::output
