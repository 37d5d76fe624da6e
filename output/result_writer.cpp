#include "output/result_writer.h"

#include <filesystem>

#include "core/atomic_file.h"
#include "core/error.h"
#include "geometry/mesh_io.h"
#include "vision/dataset.h"

namespace subflow::output {

namespace fs = std::filesystem;

void PrepareOutputDirectory(const std::string& directory, bool overwrite, bool resume) {
  std::error_code error;
  if (fs::exists(directory, error)) {
    if (!fs::is_directory(directory, error))
      ThrowError(directory, "", "exists and is not a directory");
    if (!fs::is_empty(directory, error) && !overwrite && !resume)
      ThrowError(directory, "",
                 "output directory exists and is not empty; choose another or pass --overwrite");
    // Replacing a result: remove the previous one's entries, so that none of its files
    // (a frame beyond the new run's last) passes for part of the new result. Other files
    // of the directory are the user's and stay.
    for (const char* entry : kResultEntries) {
      if (resume && (std::string(entry) == "stages" || std::string(entry) == "plan")) continue;
      fs::remove_all(fs::path(directory) / entry, error);
      if (error) ThrowError((fs::path(directory) / entry).string(), "", "cannot remove: " + error.message());
    }
    return;
  }
  fs::create_directories(directory, error);
  if (error) ThrowError(directory, "", "cannot create the output directory: " + error.message());
}

void WriteResultMeshes(const std::string& directory, int first_frame, const geometry::Faces& faces,
                       const std::vector<geometry::Positions>& positions,
                       const std::map<std::string, std::vector<Eigen::VectorXd>>& per_frame_properties) {
  const fs::path meshes = fs::path(directory) / "meshes";
  std::error_code error;
  fs::create_directories(meshes, error);
  if (error) ThrowError(meshes.string(), "", "cannot create the directory: " + error.message());
  const int frame_count = static_cast<int>(positions.size());
  for (int i = 0; i < frame_count; ++i) {
    const geometry::Positions& V = positions[i];
    if (V.rows() != positions.front().rows())
      ThrowError(meshes.string(), "frame " + std::to_string(first_frame + i),
                 "expected the same vertex count at every frame");
    const geometry::Positions motion =
        i + 1 < frame_count ? geometry::Positions(positions[i + 1] - V)
                            : geometry::Positions(geometry::Positions::Zero(V.rows(), 3));
    std::map<std::string, Eigen::VectorXd> properties;
    for (const auto& [name, values] : per_frame_properties) properties[name] = values.at(i);
    WriteResultMesh(directory, first_frame + i, faces, V, motion, properties);
  }
}

void WriteResultMesh(const std::string& directory, int frame, const geometry::Faces& faces,
                     const geometry::Positions& V, const geometry::Positions& motion,
                     const std::map<std::string, Eigen::VectorXd>& extra) {
  geometry::VertexProperties properties;
  properties.names = {"vx", "vy", "vz"};
  for (int axis = 0; axis < 3; ++axis) properties.values[properties.names[axis]] = motion.col(axis);
  for (const auto& [name, values] : extra) {
    properties.names.push_back(name);
    properties.values[name] = values;
  }
  geometry::WriteMesh((fs::path(directory) / "meshes" / (vision::FrameName(frame) + ".ply")).string(),
                      geometry::TriangleMesh{V, faces}, &properties);
}

void WriteJsonFile(const std::string& path, const nlohmann::json& json) {
  WriteFileAtomically(path, json.dump(2) + "\n");
}

}  // namespace subflow::output
