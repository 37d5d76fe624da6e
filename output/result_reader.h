// Reading a reconstruction result (../shared/OUTPUT.md, version 1) for the exports:
//   <folder>/meshes/<frame>.ply   one PLY per frame, frames contiguous, every frame the
//                                 same vertex count, order and faces
//   <folder>/report.json          a JSON object (what was run)
// Opening checks the layout without reading the vertex data: that the folder is a result
// at all (both entries present), that no frame between the first and the last is
// missing, and that every frame's PLY header announces the first frame's vertex and face
// counts. ReadFrame then parses one frame and checks its faces against the first frame's,
// so an export streams the sequence frame by frame in constant memory.
// Every problem throws subflow::Error naming the file and what was expected.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/mesh_io.h"
#include "geometry/triangle_mesh.h"

namespace subflow::output {

// One frame of a result: positions (#V×3, world units) and the per-vertex properties of
// its PLY (vx vy vz = motion to the next frame, rigid_v*, nonrigid_v*, ...).
struct ResultFrame {
  int frame = 0;  // frame index as in the file name
  geometry::Positions V;
  geometry::VertexProperties properties;

  // The #V×3 vector property (<prefix>x, <prefix>y, <prefix>z), e.g. prefix "v" for the
  // scene flow or "nonrigid_v" for its non-rigid part; throws naming `source` when absent.
  geometry::Positions Vectors(const std::string& prefix, const std::string& source) const;
};

class ResultReader {
 public:
  // Opens and checks the layout of the result in `folder` (see the file comment).
  explicit ResultReader(const std::string& folder);

  const std::string& folder() const { return folder_; }
  int first_frame() const { return first_frame_; }
  int frame_count() const { return static_cast<int>(paths_.size()); }
  int vertex_count() const { return vertex_count_; }
  int face_count() const { return static_cast<int>(faces_.rows()); }
  const geometry::Faces& faces() const { return faces_; }  // of the first frame
  const nlohmann::json& report() const { return report_; }
  // meshes/<frame>.ply of sequence index i (frame first_frame() + i).
  const std::string& MeshPath(int index) const { return paths_.at(static_cast<std::size_t>(index)); }

  // Parses sequence index `index` (0..frame_count()-1); throws naming the file when its
  // vertex count or faces differ from the first frame's.
  ResultFrame ReadFrame(int index) const;

 private:
  std::string folder_;
  int first_frame_ = 0;
  int vertex_count_ = 0;
  std::vector<std::string> paths_;
  geometry::Faces faces_;
  nlohmann::json report_;
};

// Opens `folder` and reads every frame: the complete check of a result (for tests and
// fuzzers). Throws subflow::Error on the first problem.
void CheckResultFolder(const std::string& folder);

}  // namespace subflow::output
