#include "output/result_files.h"

#include <filesystem>

#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

void WriteHullFiles(const std::string& out, const geometry::TriangleMesh& base_mesh, int first_frame,
                    const std::vector<geometry::TriangleMesh>& hulls, geometry::PlyFormat format) {
  const fs::path root(out);
  fs::create_directories(root / "hull");
  geometry::WriteMesh((root / "base_mesh.ply").string(), base_mesh, nullptr, format);
  for (std::size_t i = 0; i < hulls.size(); ++i) WriteHullFile(out, first_frame + static_cast<int>(i), hulls[i], format);
}

void WriteHullFile(const std::string& out, int frame, const geometry::TriangleMesh& hull, geometry::PlyFormat format) {
  const fs::path directory = fs::path(out) / "hull";
  fs::create_directories(directory);
  geometry::WriteMesh((directory / (vision::FrameName(frame) + ".ply")).string(), hull, nullptr, format);
}

std::string ControlFilePath(const std::string& out, int frame, int level) {
  return (fs::path(out) / "control" / vision::FrameName(frame) / ("level_" + std::to_string(level) + ".ply"))
      .string();
}

namespace {

void WriteControlFile(const std::string& out, const geometry::LoopHierarchy& hierarchy, int frame, int level,
                      const geometry::Positions& control, geometry::PlyFormat format) {
  const std::string path = ControlFilePath(out, frame, level);
  fs::create_directories(fs::path(path).parent_path());
  geometry::WriteMesh(path, geometry::TriangleMesh{control, hierarchy.LevelFaces(level)}, nullptr, format);
}

}  // namespace

void WriteControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                       const std::vector<std::vector<geometry::Positions>>& levels, geometry::PlyFormat format) {
  for (std::size_t i = 0; i < levels.size(); ++i)
    WriteFrameControlFiles(out, hierarchy, first_frame + static_cast<int>(i), levels[i], format);
}

void WriteFrameControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int frame,
                            const std::vector<geometry::Positions>& levels, geometry::PlyFormat format) {
  for (std::size_t level = 0; level < levels.size(); ++level)
    WriteControlFile(out, hierarchy, frame, static_cast<int>(level), levels[level], format);
}

void WriteFinestControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                             const std::vector<geometry::Positions>& finest, geometry::PlyFormat format) {
  for (std::size_t i = 0; i < finest.size(); ++i)
    WriteControlFile(out, hierarchy, first_frame + static_cast<int>(i), hierarchy.finest_level(), finest[i], format);
}

void WriteObjSequence(const std::string& out, int first_frame, const geometry::Faces& faces,
                      const std::vector<geometry::Positions>& positions) {
  for (std::size_t i = 0; i < positions.size(); ++i)
    WriteObjFile(out, first_frame + static_cast<int>(i), faces, positions[i]);
}

void WriteObjFile(const std::string& out, int frame, const geometry::Faces& faces, const geometry::Positions& V) {
  const fs::path directory = fs::path(out) / "obj";
  fs::create_directories(directory);
  geometry::WriteMesh((directory / (vision::FrameName(frame) + ".obj")).string(), geometry::TriangleMesh{V, faces});
}

}  // namespace subflow::output
