// Files the hull and reconstruct subcommands write beside the OUTPUT.md layout:
//   <out>/hull/<frame>.ply                 visual hull of each frame
//   <out>/base_mesh.ply                    the base mesh T0
//   <out>/control/<frame>/level_<i>.ply    control meshes of levels 0..n of each frame
//   <out>/obj/<frame>.obj                  the output surface as OBJ (reconstruct)
#pragma once

#include <string>
#include <vector>

#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "solver/shape/shape_init.h"

namespace subflow::output {

// hull/<frame>.ply and base_mesh.ply.
void WriteHullFiles(const std::string& out, const solver::ShapeInitResult& result);

// control/<frame>/level_<i>.ply; levels[f] holds the control points of levels 0..n of
// frame first_frame + f.
void WriteControlFiles(const std::string& out, const geometry::LoopHierarchy& hierarchy,
                       int first_frame, const std::vector<std::vector<geometry::Positions>>& levels);

// obj/<frame>.obj for every frame's vertices (same faces).
void WriteObjSequence(const std::string& out, int first_frame, const geometry::Faces& faces,
                      const std::vector<geometry::Positions>& positions);

}  // namespace subflow::output
