#include "output/result_reader.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "core/error.h"
#include "vision/dataset.h"

namespace subflow::output {
namespace {

namespace fs = std::filesystem;

struct PlyCounts {
  long long vertices = -1, faces = -1;
};

// The element counts a PLY header announces (the body is parsed by geometry/ply_io).
PlyCounts ReadPlyHeaderCounts(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "", "cannot open for reading");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0)
    ThrowError(path, "header", "not a PLY file (expected the magic line \"ply\")");
  PlyCounts counts;
  constexpr std::size_t kMaxHeaderBytes = 1 << 20;
  std::size_t header_bytes = line.size();
  while (std::getline(in, line)) {
    header_bytes += line.size() + 1;
    if (header_bytes > kMaxHeaderBytes) break;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line == "end_header") {
      if (counts.vertices < 0 || counts.faces < 0)
        ThrowError(path, "header", "expected elements \"vertex\" and \"face\"");
      return counts;
    }
    std::istringstream words(line);
    std::string keyword, name;
    long long count = -1;
    if (!(words >> keyword) || keyword != "element") continue;
    if (!(words >> name >> count) || count < 0)
      ThrowError(path, "header", "malformed element line \"" + line + "\"");
    if (name == "vertex") counts.vertices = count;
    if (name == "face") counts.faces = count;
  }
  ThrowError(path, "header", "no end_header within the first MiB");
}

nlohmann::json ReadReport(const fs::path& path) {
  std::ifstream in(path);
  if (!in) ThrowError(path.string(), "", "cannot open for reading");
  nlohmann::json report = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (report.is_discarded()) ThrowError(path.string(), "", "not valid JSON");
  if (!report.is_object()) ThrowError(path.string(), "", "expected a JSON object");
  return report;
}

}  // namespace

geometry::Positions ResultFrame::Vectors(const std::string& prefix, const std::string& source) const {
  geometry::Positions vectors(V.rows(), 3);
  const char* axes[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const auto found = properties.values.find(prefix + axes[axis]);
    if (found == properties.values.end() || found->second.size() != V.rows())
      ThrowError(source, "vertex property " + prefix + axes[axis],
                 "missing (expected float " + prefix + "x " + prefix + "y " + prefix + "z)");
    vectors.col(axis) = found->second;
  }
  return vectors;
}

ResultReader::ResultReader(const std::string& folder) : folder_(folder) {
  const fs::path root(folder);
  std::error_code error;
  if (!fs::is_directory(root, error)) ThrowError(folder, "", "no such directory (expected a result folder)");
  const fs::path meshes = root / "meshes", report = root / "report.json";
  if (!fs::is_directory(meshes, error) || !fs::is_regular_file(report, error))
    ThrowError(folder, "", "not a subflow result folder (expected meshes/<frame>.ply and report.json)");
  report_ = ReadReport(report);

  static const std::regex kFrameName("([0-9]{6})\\.ply");
  std::map<int, std::string> frames;
  for (const fs::directory_entry& entry : fs::directory_iterator(meshes, error)) {
    std::smatch match;
    const std::string name = entry.path().filename().string();
    if (std::regex_match(name, match, kFrameName)) frames[std::stoi(match[1])] = entry.path().string();
  }
  if (error) ThrowError(meshes.string(), "", "cannot list the directory: " + error.message());
  if (frames.empty()) ThrowError(meshes.string(), "", "no frame (expected <frame>.ply, e.g. 000000.ply)");
  first_frame_ = frames.begin()->first;
  const int last = frames.rbegin()->first;
  for (int frame = first_frame_; frame <= last; ++frame) {
    const auto found = frames.find(frame);
    if (found == frames.end())
      ThrowError((meshes / (vision::FrameName(frame) + ".ply")).string(), "",
                 "missing frame (the result has frames " + vision::FrameName(first_frame_) + " to " +
                     vision::FrameName(last) + ")");
    paths_.push_back(found->second);
  }

  geometry::MeshReadOptions options;
  options.require_manifold = false;
  const geometry::TriangleMesh first = geometry::ReadMesh(paths_.front(), options);
  faces_ = first.F;
  vertex_count_ = first.vertex_count();
  if (vertex_count_ == 0 || faces_.rows() == 0)
    ThrowError(paths_.front(), "", "no vertex or no face (expected a surface)");
  for (const std::string& path : paths_) {
    const PlyCounts counts = ReadPlyHeaderCounts(path);
    if (counts.vertices != vertex_count_ || counts.faces != faces_.rows())
      ThrowError(path, "header",
                 std::to_string(counts.vertices) + " vertices and " + std::to_string(counts.faces) +
                     " faces, expected " + std::to_string(vertex_count_) + " and " +
                     std::to_string(faces_.rows()) + " as in " + paths_.front() +
                     " (every frame of a result has the same vertices and faces)");
  }
}

ResultFrame ResultReader::ReadFrame(int index) const {
  if (index < 0 || index >= frame_count())
    ThrowError(folder_, "frame index " + std::to_string(index),
               "out of range [0, " + std::to_string(frame_count()) + ")");
  const std::string& path = paths_[static_cast<std::size_t>(index)];
  geometry::MeshReadOptions options;
  options.require_manifold = false;
  ResultFrame frame;
  frame.frame = first_frame_ + index;
  geometry::TriangleMesh mesh = geometry::ReadMesh(path, options, &frame.properties);
  if (mesh.V.rows() != vertex_count_)
    ThrowError(path, "", std::to_string(mesh.V.rows()) + " vertices, expected " +
                             std::to_string(vertex_count_) + " as in " + paths_.front());
  if (mesh.F.rows() != faces_.rows() || mesh.F != faces_)
    ThrowError(path, "faces", "differ from the faces of " + paths_.front() +
                                  " (every frame of a result has the same faces)");
  frame.V = std::move(mesh.V);
  return frame;
}

void CheckResultFolder(const std::string& folder) {
  const ResultReader reader(folder);
  for (int i = 0; i < reader.frame_count(); ++i) reader.ReadFrame(i);
}

}  // namespace subflow::output
