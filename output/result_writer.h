// Writing results in the layout of ../shared/OUTPUT.md:
//   <out>/meshes/<frame>.ply   binary little-endian PLY, float x y z, float vx vy vz (motion
//                              to the next frame, zero at the last), same vertex order and
//                              faces at every frame, extra float vertex properties after.
//   <out>/report.json          written by the caller (see WriteJsonFile).
// Nothing the user had is overwritten: PrepareOutputDirectory refuses a non-empty
// directory unless asked to overwrite, and every file is written to a temporary name and
// renamed.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/triangle_mesh.h"

namespace subflow::output {

// What a result directory holds (this layout and output/result_files.h): the entries
// --overwrite replaces.
// "stages" holds reconstruct's stage folders (docs/stages.md), "plan" the plan a take
// longer than reconstruct's --chunk runs as (docs/cluster.md).
inline constexpr const char* kResultEntries[] = {"meshes", "report.json", "hull", "base_mesh.ply",
                                                 "control", "obj", "stages", "plan"};

// Creates `directory` (and its parents). Throws subflow::Error naming it when it exists
// and is not empty and neither `overwrite` nor `resume` is set, or when it cannot be
// created. With `overwrite`, removes the kResultEntries it holds (other files stay); with
// `resume` (reconstruct --resume), the same but for "stages" and "plan", whose complete
// stage folders and finished tasks the run reuses.
void PrepareOutputDirectory(const std::string& directory, bool overwrite, bool resume = false);

// Writes <directory>/meshes/<frame>.ply for frames first_frame + i, i = 0..#positions − 1.
// positions[i] is the tessellation's #V×3 vertices at that frame (all the same #V), faces
// shared. per_frame_properties (optional) adds float vertex properties: name → one #V
// vector per frame.
void WriteResultMeshes(const std::string& directory, int first_frame, const geometry::Faces& faces,
                       const std::vector<geometry::Positions>& positions,
                       const std::map<std::string, std::vector<Eigen::VectorXd>>& per_frame_properties = {});
// One frame of WriteResultMeshes: <directory>/meshes/<frame>.ply (the directory exists)
// with vertices V, vx vy vz = `motion` (#V×3) and `properties` (one value per vertex each,
// written in the map's order after vx vy vz).
void WriteResultMesh(const std::string& directory, int frame, const geometry::Faces& faces,
                     const geometry::Positions& V, const geometry::Positions& motion,
                     const std::map<std::string, Eigen::VectorXd>& properties = {});

// Writes `json` pretty-printed to `path` (through "<path>.tmp" and a rename).
void WriteJsonFile(const std::string& path, const nlohmann::json& json);

}  // namespace subflow::output
