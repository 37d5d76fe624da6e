// Files the stage folders and results write beside the OUTPUT.md layout:
//   <out>/hull/<frame>.ply                 visual hull of each frame
//   <out>/base_mesh.ply                    the base mesh T0
//   <out>/control/<frame>/level_<i>.ply    control meshes of levels 0..n of each frame
//   <out>/obj/<frame>.obj                  the output surface as OBJ (reconstruct)
// PLY as float (results) or, for stage folders that a later stage reads back, as double
// (geometry::PlyFormat::kBinaryLittleEndianDouble).
#pragma once

#include <string>
#include <vector>

#include "geometry/loop_hierarchy.h"
#include "geometry/mesh_io.h"
#include "geometry/triangle_mesh.h"

namespace subflow::output {

// hull/<frame>.ply for frames first_frame + i, and base_mesh.ply.
void WriteHullFiles(const std::string& out, const geometry::TriangleMesh& base_mesh, int first_frame,
                    const std::vector<geometry::TriangleMesh>& hulls,
                    geometry::PlyFormat format = geometry::PlyFormat::kBinaryLittleEndian);

// hull/<frame>.ply of one frame (the directory is created when missing).
void WriteHullFile(const std::string& out, int frame, const geometry::TriangleMesh& hull,
                   geometry::PlyFormat format = geometry::PlyFormat::kBinaryLittleEndian);

// control/<frame>/level_<i>.ply; levels[f] holds the control points of levels 0..k of
// frame first_frame + f (k ≤ n).
void WriteControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                       const std::vector<std::vector<geometry::Positions>>& levels,
                       geometry::PlyFormat format = geometry::PlyFormat::kBinaryLittleEndian);
// control/<frame>/level_<i>.ply of one frame: levels[i] holds level i's control points.
void WriteFrameControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int frame,
                            const std::vector<geometry::Positions>& levels,
                            geometry::PlyFormat format = geometry::PlyFormat::kBinaryLittleEndian);
// control/<frame>/level_<n>.ply alone: each frame's finest control points.
void WriteFinestControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy, int first_frame,
                             const std::vector<geometry::Positions>& finest, geometry::PlyFormat format);
// The path of control/<frame>/level_<level>.ply below `out`.
std::string ControlFilePath(const std::string& out, int frame, int level);

// obj/<frame>.obj for every frame's vertices (same faces).
void WriteObjSequence(const std::string& out, int first_frame, const geometry::Faces& faces,
                      const std::vector<geometry::Positions>& positions);
// obj/<frame>.obj of one frame (the directory is created when missing).
void WriteObjFile(const std::string& out, int frame, const geometry::Faces& faces, const geometry::Positions& V);

}  // namespace subflow::output
