// `subflow check MESH`: reads a mesh, validates it (geometry/mesh_validation.h) and
// prints the figures. Exit status 0 when the mesh is valid, 1 when it is invalid or
// cannot be read (one-line error on stderr).
#include <iostream>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/mesh_io.h"
#include "geometry/mesh_validation.h"

namespace subflow::cli {
namespace {

struct CheckSettings {
  std::string mesh_path;
  bool json = false;
  bool no_self_intersections = false;
};

void RunCheck(const CheckSettings& settings) {
  const Stopwatch read_start;
  geometry::MeshReadOptions read_options;
  read_options.require_manifold = false;  // the validation reports non-manifoldness itself
  const geometry::TriangleMesh mesh = geometry::ReadMesh(settings.mesh_path, read_options);
  const double read_seconds = read_start.Seconds();

  geometry::MeshValidationOptions options;
  options.check_self_intersections_cgal = !settings.no_self_intersections;
  options.check_self_intersections_tetgen = !settings.no_self_intersections;
  const Stopwatch validate_start;
  const geometry::MeshValidationReport report =
      geometry::ValidateMesh(mesh, options, settings.mesh_path);
  const double validate_seconds = validate_start.Seconds();

  if (settings.json) {
    nlohmann::ordered_json json;
    json["file"] = settings.mesh_path;
    json.update(nlohmann::ordered_json::parse(report.ToJson()));
    json["seconds"] = {{"read", read_seconds}, {"validate", validate_seconds}};
    std::cout << json.dump(2) << "\n";
  } else {
    std::cout << "file:       " << settings.mesh_path << "\n"
              << report.FullReport() << "time:       read " << read_seconds << " s, validate "
              << validate_seconds << " s\n";
  }
  std::cout.flush();
  if (!report.valid()) {
    std::string reasons;
    for (const std::string& problem : report.problems)
      reasons += (reasons.empty() ? "" : "; ") + problem;
    ThrowError(settings.mesh_path, "", "invalid mesh: " + reasons);
  }
}

}  // namespace

Command AddCheckCommand(CLI::App& app) {
  auto settings = std::make_shared<CheckSettings>();
  CLI::App* command = app.add_subcommand(
      "check",
      "Validate a triangle mesh (.ply or .obj): manifold, orientation, closedness, genus, volume, "
      "self-intersections (CGAL and TetGen); exit status 0 when valid");
  command->add_option("MESH", settings->mesh_path, "The mesh file (.ply or .obj)")->required();
  command->add_flag("--json", settings->json,
                    "Print the figures as one JSON object instead of text");
  command->add_flag("--no-self-intersections", settings->no_self_intersections,
                    "Skip the CGAL and TetGen self-intersection tests (the slowest part)");
  command->footer(
      "Prints: element counts, closedness and boundary loops, manifoldness (fins, bowties), "
      "orientation "
      "(consistent, outward), components, Euler characteristic and genus, signed enclosed volume, "
      "area, "
      "bounds, edge lengths, degenerate faces, and the self-intersections found by CGAL's "
      "Polygon_mesh_processing and, independently, by TetGen's -d switch, with whether they "
      "agree.\n"
      "A mesh is valid when its coordinates are finite, it is a 2-manifold (no edge with more than "
      "two "
      "faces, no bowtie vertex), consistently oriented, oriented outward if closed (positive "
      "enclosed "
      "volume), and neither self-intersection test finds an intersection. Open boundaries, "
      "degenerate "
      "faces and unused vertices are reported as warnings.\n"
      "Exit status: 0 valid; 1 invalid or unreadable (the reason on stderr in one line).");
  return {command, [settings] { RunCheck(*settings); }};
}

}  // namespace subflow::cli
