// `subflow export RESULT --format F --out PATH`: the result (OUTPUT.md layout) as files
// other tools open as an animation, all on the result's one connectivity:
//   pc2, mdd   point caches for Blender's Mesh Cache modifier, with PATH's .obj beside
//              them (the first frame, same vertex order): output/point_cache.h
//   glb        glTF 2.0 binary, morph target per frame + animation: output/glb_writer.h
//   obj, ply   a sequence PATH/<frame>.obj|.ply (PLY keeps the flow properties)
// Writes PATH.report.json (PATH/report.json for sequences). Refuses existing outputs
// unless --overwrite.
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "output/report.h"
#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/mesh_io.h"
#include "output/glb_writer.h"
#include "output/overwrite_guard.h"
#include "output/point_cache.h"
#include "output/result_metadata.h"
#include "output/result_reader.h"
#include "output/result_writer.h"
#include "vision/dataset.h"

namespace subflow::cli {
namespace {

namespace fs = std::filesystem;

struct ExportArguments {
  std::string result;
  std::string format;
  std::string out;
  std::string dataset;
  std::optional<double> fps;
  std::string colour = "none";
  std::string up = "+z";
  bool no_normals = false;
  bool no_sparse = false;
  bool overwrite = false;
};

// "+x" ... "-z" → unit vector; throws naming --up otherwise.
Eigen::Vector3d ParseAxis(const std::string& text) {
  static const std::map<std::string, Eigen::Vector3d> kAxes = {
      {"+x", Eigen::Vector3d::UnitX()}, {"-x", -Eigen::Vector3d::UnitX()}, {"+y", Eigen::Vector3d::UnitY()},
      {"-y", -Eigen::Vector3d::UnitY()}, {"+z", Eigen::Vector3d::UnitZ()}, {"-z", -Eigen::Vector3d::UnitZ()}};
  const auto found = kAxes.find(text);
  if (found == kAxes.end()) ThrowError("--up", "", "expected +x, -x, +y, -y, +z or -z, got \"" + text + "\"");
  return found->second;
}

// The .obj written beside a point cache: PATH with its extension replaced.
std::string BaseObjPath(const std::string& out) { return fs::path(out).replace_extension(".obj").string(); }

nlohmann::json ExportSequence(const output::ResultReader& result, const ExportArguments& arguments) {
  output::PrepareOutputDirectory(arguments.out, arguments.overwrite);
  ProgressBar progress;
  ProgressBegin(&progress, arguments.format + " sequence", static_cast<std::size_t>(result.frame_count()));
  for (int i = 0; i < result.frame_count(); ++i) {
    const output::ResultFrame frame = result.ReadFrame(i);
    const std::string path = (fs::path(arguments.out) / (vision::FrameName(frame.frame) + "." + arguments.format)).string();
    geometry::WriteMesh(path, geometry::TriangleMesh{frame.V, result.faces()},
                        arguments.format == "ply" ? &frame.properties : nullptr);
    ProgressUpdate(&progress, static_cast<std::size_t>(i + 1));
  }
  ProgressEnd(&progress);
  return {{"files", result.frame_count()}};
}

void RunExport(const ExportArguments& arguments) {
  const Stopwatch stopwatch;
  const std::string& format = arguments.format;
  const bool sequence = format == "obj" || format == "ply";
  const output::ResultReader result(arguments.result);
  const output::ResultMetadata metadata =
      output::ResolveResultMetadata(result, arguments.dataset, arguments.fps);
  if (!sequence) output::CheckOutputFile(arguments.out, arguments.overwrite, "");
  if (format == "pc2" || format == "mdd") output::CheckOutputFile(BaseObjPath(arguments.out), arguments.overwrite, "");
  if (metadata.fps_source == "default" && (format == "mdd" || format == "glb"))
    spdlog::warn("no frame rate in {}/report.json or its dataset's cameras.json: assuming {} fps (pass --fps)",
                 arguments.result, metadata.fps);

  nlohmann::json details;
  ProgressBar progress;
  if (format == "pc2") {
    output::WritePc2(result, arguments.out, static_cast<float>(result.first_frame()), &progress);
    output::WriteBaseObj(result, BaseObjPath(arguments.out));
    details["base_obj"] = BaseObjPath(arguments.out);
  } else if (format == "mdd") {
    output::WriteMdd(result, arguments.out, metadata.fps, &progress);
    output::WriteBaseObj(result, BaseObjPath(arguments.out));
    details["base_obj"] = BaseObjPath(arguments.out);
  } else if (format == "glb") {
    output::GlbOptions options;
    options.fps = metadata.fps;
    options.normals = !arguments.no_normals;
    options.sparse = !arguments.no_sparse;
    options.up = ParseAxis(arguments.up);
    options.colours = arguments.colour != "none";
    if (options.colours) {
      options.colour_flow = output::ParseFlowKind(arguments.colour, "--color");
      const output::FlowRange range = output::SequenceFlowRange(result, options.colour_flow);
      options.colour_scale.min = range.min;
      options.colour_scale.max = range.max;
      details["colour_range"] = {range.min, range.max};
    }
    const output::GlbSummary summary = output::WriteGlb(result, arguments.out, options, &progress);
    details["morph_targets"] = summary.morph_targets;
    details["sparse_targets"] = summary.sparse_targets;
  } else {
    details = ExportSequence(result, arguments);
  }
  const double seconds = stopwatch.Seconds();
  std::error_code error;
  const auto bytes = sequence ? 0 : fs::file_size(arguments.out, error);
  const std::string report_path =
      sequence ? (fs::path(arguments.out) / "report.json").string() : arguments.out + ".report.json";
  if (!sequence) output::CheckOutputFile(report_path, true, "");
  output::WriteJsonFile(report_path, {{"command", "export"},
                                      {"arguments", InvocationArguments()},
                                      {"versions", output::VersionsJson()},
                                      {"result", arguments.result},
                                      {"format", format},
                                      {"out", arguments.out},
                                      {"frames", result.frame_count()},
                                      {"first_frame", result.first_frame()},
                                      {"vertices", result.vertex_count()},
                                      {"faces", result.face_count()},
                                      {"fps", metadata.fps},
                                      {"fps_source", metadata.fps_source},
                                      {"bytes", bytes},
                                      {"details", details},
                                      {"seconds", seconds}});
  std::cout << arguments.out << ": " << format << ", " << result.frame_count() << " frames of "
            << result.vertex_count() << " vertices";
  if (!sequence) std::cout << ", " << bytes << " bytes";
  if (format == "mdd" || format == "glb") std::cout << ", " << metadata.fps << " fps (" << metadata.fps_source << ")";
  std::cout << " in " << seconds << " s\n";
}

}  // namespace

Command AddExportCommand(CLI::App& app) {
  auto arguments = std::make_shared<ExportArguments>();
  CLI::App* command = app.add_subcommand(
      "export", "Write a result as an animation other tools open: Blender point caches (pc2, mdd + base "
                "obj), glTF binary with one morph target per frame (glb), or obj/ply sequences.");
  command->add_option("RESULT", arguments->result, "Result folder (meshes/<frame>.ply, report.json)")->required();
  command->add_option("--format,-f", arguments->format, "pc2, mdd, glb, obj or ply")
      ->required()
      ->check(CLI::IsMember({"pc2", "mdd", "glb", "obj", "ply"}));
  command->add_option("--out,-o", arguments->out,
                      "Output file (pc2, mdd: the base .obj is written beside it; glb) or directory (obj, ply)")
      ->required();
  command->add_option("--dataset", arguments->dataset,
                      "Dataset of the result, for its fps and units (default: report.json's dataset.directory)");
  command->add_option("--fps", arguments->fps, "Frames per second (default: report.json, then the dataset's "
                      "cameras.json, then 30)");
  command->add_option("--color", arguments->colour, "glb: per-vertex COLOR_0 by flow magnitude: none, flow or nonrigid")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "flow", "nonrigid"}));
  command->add_option("--up", arguments->up, "glb: the world's up axis, turned to glTF's +Y (+x -x +y -y +z -z)")
      ->capture_default_str();
  command->add_flag("--no-normals", arguments->no_normals, "glb: no NORMAL attribute (flat shading, smaller file)");
  command->add_flag("--no-sparse", arguments->no_sparse, "glb: always store morph targets dense");
  command->add_flag("--overwrite", arguments->overwrite, "Replace existing output files");
  command->footer(
      "Blender: import the .obj (Forward +Y, Up +Z), add a Mesh Cache modifier, choose the .pc2 or .mdd; or "
      "File > Import > glTF for the .glb.\nExample: subflow export out/result --format glb --color flow --out blob.glb");
  return {command, [arguments] { RunExport(*arguments); }};
}

}  // namespace subflow::cli
