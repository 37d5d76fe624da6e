#include "output/report.h"

#include <cmath>
#include <filesystem>

#include <CGAL/version.h>
#include <Eigen/Core>
#include <opencv2/core/version.hpp>
#include <spdlog/version.h>

#include "output/options_json.h"

namespace subflow::output {
namespace {

nlohmann::json Finite(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(); }

nlohmann::json Vector3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json VersionsJson() {
  return {{"subflow", SUBFLOW_VERSION},
          {"libraries",
           {{"eigen", std::to_string(EIGEN_WORLD_VERSION) + "." + std::to_string(EIGEN_MAJOR_VERSION) +
                          "." + std::to_string(EIGEN_MINOR_VERSION)},
            {"cgal", CGAL_VERSION_STR},
            {"opencv", CV_VERSION},
            {"spdlog", std::to_string(SPDLOG_VER_MAJOR) + "." + std::to_string(SPDLOG_VER_MINOR) +
                           "." + std::to_string(SPDLOG_VER_PATCH)}}}};
}

nlohmann::json DatasetJson(const vision::Dataset& dataset) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& camera : dataset.cameras())
    cameras.push_back({{"name", camera.name()}, {"width", camera.width()}, {"height", camera.height()}});
  // fps and units are what the exports need to play and label the result (null = absent).
  return {{"directory", std::filesystem::absolute(dataset.directory()).lexically_normal().string()},
          {"frames", dataset.frame_count()},
          {"fps", dataset.fps() ? nlohmann::json(*dataset.fps()) : nlohmann::json()},
          {"units", dataset.units().empty() ? nlohmann::json() : nlohmann::json(dataset.units())},
          {"cameras", cameras},
          {"bounds", {{"min", Vector3(dataset.bounds().min)}, {"max", Vector3(dataset.bounds().max)},
                      {"from_file", dataset.bounds_from_file()}}},
          {"has_masks", dataset.has_masks()},
          {"has_background", dataset.has_background()},
          {"has_videos", dataset.has_videos()},
          {"warnings", dataset.warnings()}};
}

nlohmann::json ReportHead(const CommandRun& run, const vision::Dataset& dataset) {
  return {{"command", run.command},
          {"arguments", run.arguments},
          {"output", run.out},
          {"overwrite", run.overwrite},
          {"resume", run.resume},
          {"versions", VersionsJson()},
          {"dataset", DatasetJson(dataset)}};
}

namespace {

nlohmann::json ConcavitiesJson(const vision::ConcavityCarvingReport& r) {
  return {{"applied", r.applied},           {"skipped", r.skipped},
          {"hull_voxels", r.hull_voxels},   {"carved_voxels", r.carved_voxels},
          {"removed_voxels", r.removed_voxels}, {"trusted_pixels", r.trusted_pixels},
          {"seconds", r.seconds}};
}

nlohmann::json RegistrationJson(const solver::SurfaceRegistrationReport& r) {
  return {{"applied", r.applied},
          {"iterations", r.iterations},
          {"mean_surface_distance_before", r.mean_surface_distance_before},
          {"mean_surface_distance_after", r.mean_surface_distance_after},
          {"mean_target_distance_before", r.mean_target_distance_before},
          {"mean_target_distance_after", r.mean_target_distance_after},
          {"reachable_target_distance_before", r.reachable_target_distance_before},
          {"seconds", r.seconds}};
}

// The still set's evidence, when it was used (null: not used): "method" "backdrop" or
// "photo-consistency", every camera's backdrop figures (also when not plain), and the
// photo-consistency's figures when it ran; "seconds" of the method used.
nlohmann::json StillJson(const vision::Dataset& dataset, const solver::ShapeInitResult& result) {
  if (!result.used_still) return nullptr;
  nlohmann::json backdrops = nlohmann::json::array();
  for (size_t c = 0; c < result.backdrops.size(); ++c) {
    const vision::PlainBackdrop& backdrop = result.backdrops[c];
    nlohmann::json colour = nlohmann::json::array();
    for (int channel = 0; channel < backdrop.channels; ++channel) colour.push_back(backdrop.colour[channel]);
    backdrops.push_back({{"name", dataset.camera(static_cast<int>(c)).name()},
                         {"plain", backdrop.plain},
                         {"colour", colour},
                         {"spread", backdrop.spread},
                         {"sure_pixels", backdrop.sure_pixels}});
  }
  if (result.used_backdrop)  // the photo-consistency did not run
    return {{"method", "backdrop"}, {"backdrops", backdrops}, {"seconds", result.backdrop_seconds}};
  nlohmann::json cameras = nlohmann::json::array();
  for (const vision::StillCameraReport& camera : result.still.cameras)
    cameras.push_back({{"name", camera.name}, {"planes", camera.planes}, {"depth_pixels", camera.depth_pixels},
                       {"trusted_pixels", camera.trusted_pixels}, {"support_pixels", camera.support_pixels},
                       {"silhouette_pixels", camera.silhouette_pixels}, {"sweep_seconds", camera.sweep_seconds}});
  const vision::SupportPlane& plane = result.still.support;
  return {{"method", "photo-consistency"},
          {"backdrops", backdrops},
          {"support_plane", {{"found", plane.found}, {"normal", Vector3(plane.normal)}, {"offset", plane.offset},
                             {"tolerance", plane.tolerance}, {"inliers", plane.inliers}, {"points", plane.points},
                             {"above_fraction", plane.above_fraction}}},
          {"occupied_voxels", result.still.fused.occupied_voxels},
          {"cameras", cameras},
          {"seconds", result.still.seconds}};
}

}  // namespace

nlohmann::json ShapeInitJson(const vision::Dataset& dataset, const solver::ShapeInitOptions& options,
                             const solver::ShapeInitResult& result) {
  const auto& hierarchy = *result.hierarchy;
  nlohmann::json levels = nlohmann::json::array();
  for (int level = 0; level <= hierarchy.finest_level(); ++level)
    levels.push_back({{"level", level}, {"vertices", hierarchy.VertexCount(level)},
                      {"faces", hierarchy.FaceCount(level)}});
  nlohmann::json valences = nlohmann::json::object();
  for (const auto& [valence, count] : result.simplify.valence_histogram)
    valences[std::to_string(valence)] = count;

  // Backgrounds estimated from the video (cameras without masks and background image),
  // with the free-pixel margin they were estimated with; null when none was.
  nlohmann::json estimated = nullptr;
  for (size_t c = 0; c < result.estimated_backgrounds.size(); ++c) {
    const vision::EstimatedBackground& background = result.estimated_backgrounds[c];
    if (background.frames == 0) continue;
    if (estimated.is_null())
      estimated = {{"frames", background.frames},
                   {"margin", options.silhouettes.background_estimate_margin},
                   {"seconds", result.estimate_background_seconds},
                   {"cameras", nlohmann::json::array()}};
    estimated["cameras"].push_back({{"name", dataset.camera(static_cast<int>(c)).name()},
                                    {"frames", background.frames},
                                    {"known_fraction", background.known_fraction},
                                    {"mean_free_frames", background.mean_free_frames}});
  }

  // What stands still, added to the silhouettes from estimated backgrounds (null: none).
  nlohmann::json standing = nullptr;
  for (size_t c = 0; c < result.standing.size(); ++c) {
    if (standing.is_null()) standing = nlohmann::json::array();
    standing.push_back({{"name", dataset.camera(static_cast<int>(c)).name()},
                        {"threshold", result.standing[c].threshold},
                        {"object_pixels", result.standing[c].object_pixels}});
  }
  const nlohmann::json still = StillJson(dataset, result);

  nlohmann::json frames = nlohmann::json::array();
  double carve = 0, isosurface = 0, fit = 0;
  for (const auto& frame : result.frames) {
    nlohmann::json cameras = nlohmann::json::array();
    for (const auto& camera : frame.carving.cameras)
      cameras.push_back({{"name", camera.name},
                         {"source", vision::ToString(camera.source)},
                         {"used", camera.used},
                         {"excluded", camera.excluded},
                         {"object_pixels", camera.object_pixels},
                         {"threshold", camera.threshold},
                         {"silhouette_iou", Finite(camera.silhouette_iou)}});
    nlohmann::json fit_levels = nlohmann::json::array();
    for (const auto& level : frame.fit)
      fit_levels.push_back({{"level", level.level},
                            {"mean_distance", level.mean_distance},
                            {"max_distance", level.max_distance},
                            {"misses", level.misses}});
    frames.push_back({{"frame", frame.frame},
                      {"hull_from_frame", frame.hull_from_frame},
                      {"voxel_resolution", frame.carving.resolution},
                      {"max_misses", frame.carving.max_misses},
                      {"closing_radius", frame.carving.closing_radius},
                      {"opening_radius", frame.carving.opening_radius},
                      {"carved_voxels", frame.carving.carved_voxels},
                      {"occupied_voxels", frame.carving.occupied_voxels},
                      {"components_found", frame.carving.components_found},
                      {"components_kept", frame.carving.components_kept},
                      {"cavity_voxels_filled", frame.carving.cavity_voxels_filled},
                      {"border_voxels", frame.carving.border_voxels},
                      {"concavities", ConcavitiesJson(frame.concavities)},
                      {"mean_silhouette_iou", Finite(frame.carving.mean_silhouette_iou)},
                      {"cameras", cameras},
                      {"warnings", frame.carving.warnings},
                      {"hull", {{"vertices", frame.hull_vertices}, {"faces", frame.hull_faces}}},
                      {"registration", RegistrationJson(frame.registration)},
                      {"fit", fit_levels},
                      {"seconds", {{"carve", frame.carve_seconds},
                                   {"isosurface", frame.isosurface_seconds},
                                   {"fit", frame.fit_seconds}}}});
    carve += frame.carve_seconds;
    isosurface += frame.isosurface_seconds;
    fit += frame.fit_seconds;
  }
  return {{"reference_frame", result.reference_frame},
          {"base_mesh", {{"vertices", result.base_mesh.vertex_count()},
                         {"faces", result.base_mesh.face_count()},
                         {"valence_histogram", valences},
                         {"simplify_attempts", result.simplify.attempts},
                         {"max_distance", result.simplify.max_distance},
                         {"bound_kept", result.simplify.bound_kept},
                         {"largest_sample_distance", result.simplify.largest_sample_distance},
                         {"bound_face_count", result.resolution.bound_face_count},
                         {"bound_edge_pixels", result.resolution.bound_edge_pixels},
                         {"edge_pixels", result.resolution.base_edge_pixels},
                         {"finest_edge_pixels", result.resolution.finest_edge_pixels}}},
          {"levels", levels},
          {"estimated_background", estimated},
          {"standing", standing},
          {"still", still},
          {"frames", frames},
          {"seconds", {{"carve", carve}, {"isosurface", isosurface}, {"simplify", result.simplify_seconds},
                       {"fit", fit}, {"total", result.seconds}}}};
}

nlohmann::json MotionInitJson(const solver::MotionInitOptions& o, const solver::MotionInitResult& result,
                              int first_frame) {
  nlohmann::json frames = nlohmann::json::array();
  for (const solver::MotionFrameReport& f : result.frames) {
    frames.push_back({{"frame", first_frame + f.frame},
                      {"from_frame", f.from_frame < 0 ? -1 : first_frame + f.from_frame},
                      {"identical_images", f.identical_images},
                      {"constraints", f.step.constraints},
                      {"pruned", f.step.pruned},
                      {"collinearity_pruned", f.step.collinearity_pruned},
                      {"photometric_rms_zero_motion", f.step.photometric_rms_zero},
                      {"photometric_rms", f.step.photometric_rms},
                      {"mean_displacement", f.step.mean_displacement},
                      {"cg_iterations", f.step.cg_iterations},
                      {"corrected", f.corrected},
                      {"correction_rms_before", f.correction_rms_before},
                      {"correction_rms_applied", f.correction_rms_applied},
                      {"correction_unreached", f.correction_unreached},
                      {"seconds", f.step.seconds}});
    if (f.corrected && o.registration.enabled) {
      frames.back()["registration"] = RegistrationJson(f.registration);
      if (f.unreached_before_registration >= 0.0)
        frames.back()["registration"]["unreached_before"] = f.unreached_before_registration;
    }
    if (!f.guesses_offered.empty()) {
      nlohmann::json offered = nlohmann::json::array();
      for (solver::GuessSource source : f.guesses_offered) offered.push_back(solver::ToString(source));
      frames.back()["guess"] = {{"offered", offered},
                                {"used", f.step.guess_used},
                                {"source", solver::ToString(f.guess_source())},
                                {"photometric_rms", f.step.guess_rms},
                                {"photometric_rms_zero_motion", f.step.guess_rms_zero}};
    }
  }
  return {{"options", o},
          {"reference_frame", first_frame + result.reference_frame},
          {"frames", frames},
          {"seconds", result.seconds}};
}

nlohmann::json RefinementJson(const solver::StereoRefinementOptions& o, const solver::RefinementResult& result,
                              int first_frame) {
  nlohmann::json levels = nlohmann::json::array();
  for (const solver::RefinementLevelReport& l : result.levels)
    levels.push_back({{"level", l.level}, {"dof", l.dof}, {"patches", l.patches},
                      {"active_patches", l.active_patches}, {"active_fraction", l.active_fraction},
                      {"windows", l.windows}, {"iterative_windows", l.iterative_windows},
                      {"concurrent_halves", l.concurrent_halves},
                      {"parameters", l.parameters}, {"residual_blocks", l.residual_blocks},
                      {"mean_increment", l.mean_increment}, {"iterations", l.iterations},
                      {"seconds", l.seconds}, {"solver_seconds", l.solver_seconds}});
  nlohmann::json frames = nlohmann::json::array();
  for (const solver::RefinementFrameReport& f : result.frames)
    frames.push_back({{"frame", first_frame + f.frame}, {"stereo_pairs", f.stereo_pairs},
                      {"ncc_before", f.ncc_before}, {"ncc_after", f.ncc_after},
                      {"silhouette_rms_px_before", f.silhouette_rms_before},
                      {"silhouette_rms_px_after", f.silhouette_rms_after}});
  return {{"options", o},
          {"levels", levels},
          {"frames", frames},
          {"seconds", result.seconds}};
}

nlohmann::json RigidMotionJson(const std::vector<solver::RigidMotion>& rigid, int first_frame) {
  nlohmann::json steps = nlohmann::json::array();
  for (std::size_t f = 0; f < rigid.size(); ++f)
    steps.push_back({{"from_frame", first_frame + static_cast<int>(f)},
                     {"to_frame", first_frame + static_cast<int>(f) + 1},
                     {"v", Vector3(rigid[f].v)},
                     {"omega", Vector3(rigid[f].omega)},
                     {"rotation_degrees", rigid[f].RotationAngle() * 180.0 / M_PI},
                     {"rms_residual", rigid[f].rms_residual}});
  return steps;
}

}  // namespace subflow::output
