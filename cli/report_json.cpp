#include "cli/report_json.h"

#include <cmath>

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
  return {{"directory", dataset.directory()},
          {"frames", dataset.frame_count()},
          {"cameras", cameras},
          {"bounds", {{"min", Vector3(dataset.bounds().min)}, {"max", Vector3(dataset.bounds().max)},
                      {"from_file", dataset.bounds_from_file()}}},
          {"has_masks", dataset.has_masks()},
          {"has_background", dataset.has_background()},
          {"has_videos", dataset.has_videos()}};
}

nlohmann::json ShapeInitOptionsJson(const solver::ShapeInitOptions& o) {
  return {
      {"levels", o.levels},
      {"reference_frame", o.reference_frame},
      {"first_frame", o.first_frame},
      {"frame_count", o.frame_count},
      {"silhouettes",
       {{"source", vision::ToString(o.silhouettes.source)},
        {"background_blur_sigma", o.silhouettes.background_blur_sigma},
        {"background_threshold", o.silhouettes.background_threshold},
        {"motion_sigma", o.silhouettes.motion_sigma},
        {"motion_lambda", o.silhouettes.motion_lambda},
        {"motion_window", o.silhouettes.motion_window},
        {"motion_threshold", o.silhouettes.motion_threshold},
        {"close_radius", o.silhouettes.close_radius}}},
      {"carving",
       {{"resolution", o.carving.resolution},
        {"pixels_per_voxel", o.carving.pixels_per_voxel},
        {"min_cameras", o.carving.min_cameras},
        {"max_misses", o.carving.max_misses},
        {"evidence_threshold", o.carving.evidence_threshold},
        {"closing_radius", o.carving.closing_radius},
        {"opening_radius", o.carving.opening_radius}}},
      {"isosurface",
       {{"iso_value", o.isosurface.iso_value},
        {"smoothing_sigma_voxels", o.isosurface.smoothing_sigma_voxels},
        {"facet_size_voxels", o.isosurface.facet_size_voxels},
        {"facet_distance_voxels", o.isosurface.facet_distance_voxels}}},
      {"simplify",
       {{"target_face_count", o.simplify.target_face_count},
        {"max_valence", o.simplify.max_valence},
        {"min_valence", o.simplify.min_valence}}},
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
                         {"silhouette_iou", Finite(camera.silhouette_iou)}});
    nlohmann::json fit_levels = nlohmann::json::array();
    for (const auto& level : frame.fit)
      fit_levels.push_back({{"level", level.level},
                            {"mean_distance", level.mean_distance},
                            {"max_distance", level.max_distance},
                            {"misses", level.misses}});
    frames.push_back({{"frame", frame.frame},
                      {"voxel_resolution", frame.carving.resolution},
                      {"occupied_voxels", frame.carving.occupied_voxels},
                      {"components_kept", frame.carving.components_kept},
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
            {"frames", frames},
            {"seconds", {{"carve", carve}, {"isosurface", isosurface}, {"simplify", result.simplify_seconds},
                         {"fit", fit}}}}}};
}

}  // namespace subflow::cli
