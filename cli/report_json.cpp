#include "cli/report_json.h"

#include <cmath>
#include <filesystem>

#include <CGAL/version.h>
#include <Eigen/Core>
#include <opencv2/core/version.hpp>
#include <spdlog/version.h>

namespace subflow::cli {
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
          {"has_videos", dataset.has_videos()}};
}

nlohmann::json SilhouetteOptionsJson(const vision::SilhouetteOptions& o) {
  return {{"source", vision::ToString(o.source)},
          {"background_blur_sigma", o.background_blur_sigma},
          {"background_threshold", o.background_threshold},
          {"background_method", vision::ToString(o.background_method)},
          {"background_open_radius", o.background_open_radius},
          {"background_min_threshold", o.background_min_threshold},
          {"background_contour_fraction", o.background_contour_fraction},
          {"motion_sigma", o.motion_sigma},
          {"motion_lambda", o.motion_lambda},
          {"motion_window", o.motion_window},
          {"motion_threshold", o.motion_threshold},
          {"motion_method", vision::ToString(o.motion_method)},
          {"motion_min_threshold", o.motion_min_threshold},
          {"close_radius", o.close_radius},
          {"fill_holes", o.fill_holes},
          {"min_region_pixels", o.min_region_pixels},
          {"min_object_pixels", o.min_object_pixels}};
}

nlohmann::json VoxelCarvingOptionsJson(const vision::VoxelCarvingOptions& o) {
  return {{"resolution", o.resolution},
          {"pixels_per_voxel", o.pixels_per_voxel},
          {"max_auto_resolution", o.max_auto_resolution},
          {"min_cameras", o.min_cameras},
          {"max_misses", o.max_misses},
          {"evidence_threshold", o.evidence_threshold},
          {"footprint_margin", o.footprint_margin},
          {"closing_radius", o.closing_radius},
          {"opening_radius", o.opening_radius},
          {"connectivity", o.connectivity},
          {"min_component_fraction", o.min_component_fraction},
          {"fill_cavities", o.fill_cavities},
          {"compute_silhouette_iou", o.compute_silhouette_iou},
          {"threads", o.threads}};
}

nlohmann::json ShapeInitOptionsJson(const solver::ShapeInitOptions& o) {
  return {
      {"levels", o.levels},
      {"reference_frame", o.reference_frame},
      {"first_frame", o.first_frame},
      {"frame_count", o.frame_count},
      {"silhouettes", SilhouetteOptionsJson(o.silhouettes)},
      {"carving", VoxelCarvingOptionsJson(o.carving)},
      {"isosurface",
       {{"iso_value", o.isosurface.iso_value},
        {"smoothing_sigma_voxels", o.isosurface.smoothing_sigma_voxels},
        {"padding_voxels", o.isosurface.padding_voxels},
        {"facet_angle_degrees", o.isosurface.facet_angle_degrees},
        {"facet_size_voxels", o.isosurface.facet_size_voxels},
        {"facet_distance_voxels", o.isosurface.facet_distance_voxels},
        {"max_vertex_count", o.isosurface.max_vertex_count},
        {"random_seed", o.isosurface.random_seed}}},
      {"simplify",
       {{"target_face_count", o.simplify.target_face_count},
        {"max_normal_change_degrees", o.simplify.max_normal_change_degrees},
        {"min_triangle_angle_degrees", o.simplify.min_triangle_angle_degrees},
        {"max_valence", o.simplify.max_valence},
        {"min_valence", o.simplify.min_valence},
        {"flip_rounds", o.simplify.flip_rounds},
        {"max_flip_dihedral_degrees", o.simplify.max_flip_dihedral_degrees},
        {"check_self_intersections", o.simplify.check_self_intersections},
        {"max_attempts", o.simplify.max_attempts},
        {"retry_growth", o.simplify.retry_growth}}},
      {"fit",
       {{"iterations_per_level", o.fit.iterations_per_level},
        {"max_snap_distance", o.fit.max_snap_distance}}}};
}

nlohmann::json ShapeInitReport(const vision::Dataset& dataset, const solver::ShapeInitOptions& options,
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
                      {"carved_voxels", frame.carving.carved_voxels},
                      {"occupied_voxels", frame.carving.occupied_voxels},
                      {"components_found", frame.carving.components_found},
                      {"components_kept", frame.carving.components_kept},
                      {"cavity_voxels_filled", frame.carving.cavity_voxels_filled},
                      {"border_voxels", frame.carving.border_voxels},
                      {"mean_silhouette_iou", Finite(frame.carving.mean_silhouette_iou)},
                      {"cameras", cameras},
                      {"warnings", frame.carving.warnings},
                      {"hull", {{"vertices", frame.hull.vertex_count()}, {"faces", frame.hull.face_count()}}},
                      {"fit", fit_levels},
                      {"seconds", {{"carve", frame.carve_seconds},
                                   {"isosurface", frame.isosurface_seconds},
                                   {"fit", frame.fit_seconds}}}});
    carve += frame.carve_seconds;
    isosurface += frame.isosurface_seconds;
    fit += frame.fit_seconds;
  }
  return {{"versions", VersionsJson()},
          {"dataset", DatasetJson(dataset)},
          {"options", {{"shape_init", ShapeInitOptionsJson(options)}}},
          {"shape_init",
           {{"reference_frame", result.reference_frame},
            {"base_mesh", {{"vertices", result.base_mesh.vertex_count()},
                           {"faces", result.base_mesh.face_count()},
                           {"valence_histogram", valences},
                           {"simplify_attempts", result.simplify.attempts}}},
            {"levels", levels},
            {"estimated_background", estimated},
            {"frames", frames},
            {"seconds", {{"carve", carve}, {"isosurface", isosurface}, {"simplify", result.simplify_seconds},
                         {"fit", fit}}}}}};
}

}  // namespace subflow::cli
