// `subflow subdivide IN --levels N [--limit] --out OUT`: Loop-subdivides a triangle mesh
// N times (geometry/loop_hierarchy.h) and writes the control mesh of level N, or with
// --limit its vertices pushed to their limit positions on the Loop surface. Writes
// OUT.report.json beside it (last).
#include <iostream>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/mesh_io.h"
#include "geometry/unused_vertices.h"
#include "output/overwrite_guard.h"
#include "output/report.h"
#include "output/result_writer.h"

namespace subflow::cli {
namespace {

struct SubdivideSettings {
  std::string input_path;
  std::string output_path;
  int levels = 1;
  bool limit = false;
  bool overwrite = false;
};

void RunSubdivide(const SubdivideSettings& settings) {
  const Stopwatch stopwatch;
  const std::string report_path = settings.output_path + ".report.json";
  output::CheckOutputFile(settings.output_path, settings.overwrite, "--out");
  output::CheckOutputFile(report_path, settings.overwrite, "--out");
  geometry::TriangleMesh base = geometry::ReadMesh(settings.input_path);
  if (const int unused = geometry::RemoveUnusedVertices(&base))
    spdlog::warn("{}: {} vertices referenced by no face are left out; the others keep their order",
                 settings.input_path, unused);
  const geometry::LoopHierarchy hierarchy(base.F, base.vertex_count(), settings.levels,
                                          settings.input_path);
  geometry::TriangleMesh result;
  result.V = hierarchy.Refine(base.V, 0, settings.levels);
  if (settings.limit)
    result.V = geometry::MultiplyPoints(hierarchy.LimitPositions(settings.levels), result.V);
  result.F = hierarchy.LevelFaces(settings.levels);
  geometry::WriteMesh(settings.output_path, result);
  const double seconds = stopwatch.Seconds();
  output::WriteJsonFile(report_path, {{"command", "subdivide"},
                                      {"arguments", InvocationArguments()},
                                      {"versions", output::VersionsJson()},
                                      {"input", {{"path", settings.input_path},
                                                 {"vertices", base.vertex_count()},
                                                 {"faces", base.face_count()},
                                                 {"closed", hierarchy.Topology(0).IsClosed()}}},
                                      {"output", {{"path", settings.output_path},
                                                  {"vertices", result.vertex_count()},
                                                  {"faces", result.face_count()}}},
                                      {"levels", settings.levels},
                                      {"limit", settings.limit},
                                      {"seconds", seconds}});
  std::cout << settings.input_path << ": " << base.vertex_count() << " vertices, "
            << base.face_count() << " faces"
            << (hierarchy.Topology(0).IsClosed() ? "" : " (open)") << "\n"
            << settings.output_path << ": " << result.vertex_count() << " vertices, "
            << result.face_count() << " faces, level " << settings.levels
            << (settings.limit ? ", limit positions" : ", control points") << " (" << seconds
            << " s)\n";
}

}  // namespace

Command AddSubdivideCommand(CLI::App& app) {
  auto settings = std::make_shared<SubdivideSettings>();
  CLI::App* command = app.add_subcommand(
      "subdivide",
      "Loop-subdivide a triangle mesh: each level splits every triangle into four, with "
      "Loop's original weights (as CGAL's Loop_subdivision) and crease rules on open "
      "boundaries.");
  command->add_option("IN", settings->input_path, "Input mesh (.ply or .obj), a manifold "
                      "triangle mesh, closed or open")->required();
  command->add_option("--levels,-n", settings->levels,
                      "Number of subdivision levels (0 copies the mesh; faces grow 4× per "
                      "level)")
      ->required()
      ->check(CLI::Range(0, 12));
  command->add_flag("--limit", settings->limit,
                    "Move the final vertices onto the limit surface (Loop's limit masks) "
                    "instead of writing the control points");
  command->add_option("--out,-o", settings->output_path,
                      "Output mesh (.ply or .obj), with OUT.report.json beside it; an existing file is refused without "
                      "--overwrite")
      ->required();
  command->add_flag("--overwrite", settings->overwrite, "Replace the output mesh if it exists");
  command->footer(
      "Vertex order: the input vertices keep their order (vertices no face uses are left out, with a "
      "warning); each level appends one vertex per edge of the previous level. Polygon faces are "
      "triangulated on reading, with a warning.\nExample: subflow subdivide base.ply --levels 3 "
      "--limit --out smooth.ply");
  return {command, [settings] { RunSubdivide(*settings); }};
}

}  // namespace subflow::cli
