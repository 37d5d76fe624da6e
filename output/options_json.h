// Every options struct of the pipeline as JSON, field by field, for report.json (what was
// run) and for reading recorded options back (stage reports). One line per struct lists
// its fields beside the struct's namespace; tests/output/options_json_test.cpp counts the
// fields of each struct (aggregate arity) against the keys written, so a field added to a
// struct and forgotten here fails the build of the report's tests. Keys are the field
// names; enums are written as the names the command line takes ("auto", "otsu",
// "sparse_normal_cholesky"); automatic values are recorded as given (e.g. −1).
#pragma once

#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <string>

#include <ceres/types.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "geometry/isosurface.h"
#include "geometry/simplify.h"
#include "solver/motion/motion_init.h"
#include "solver/reconstruction.h"
#include "solver/shape/shape_init.h"
#include "solver/stereo/stereo_refinement.h"
#include "vision/silhouettes.h"
#include "vision/standing_evidence.h"
#include "vision/still_evidence.h"
#include "vision/voxel_carving.h"

namespace subflow::output {

// The value of `values` whose name (ToString) is `text`; throws subflow::Error naming
// `field` otherwise.
template <typename Enum>
Enum EnumFromName(const std::string& text, std::initializer_list<Enum> values, const std::string& field) {
  std::string names;
  for (Enum value : values) {
    if (ToString(value) == text) return value;
    names += (names.empty() ? "" : ", ") + ToString(value);
  }
  ThrowError("options", field, "'" + text + "' is not one of " + names);
}

}  // namespace subflow::output

namespace ceres {

// Ceres's own names, lower case: "sparse_normal_cholesky".
inline void to_json(nlohmann::json& json, LinearSolverType type) {
  std::string name = LinearSolverTypeToString(type);
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  json = name;
}
inline void from_json(const nlohmann::json& json, LinearSolverType& type) {
  if (!StringToLinearSolverType(json.get<std::string>(), &type))
    subflow::ThrowError("options", "linear_solver", "'" + json.get<std::string>() + "' is not a Ceres linear solver");
}

}  // namespace ceres

namespace subflow::vision {

inline void to_json(nlohmann::json& json, EvidenceSource source) { json = ToString(source); }
inline void from_json(const nlohmann::json& json, EvidenceSource& source) {
  source = ParseEvidenceSource(json.get<std::string>());
}
inline void to_json(nlohmann::json& json, ThresholdMethod method) { json = ToString(method); }
inline void from_json(const nlohmann::json& json, ThresholdMethod& method) {
  method = output::EnumFromName(json.get<std::string>(), {ThresholdMethod::kOtsu, ThresholdMethod::kTriangle},
                                "threshold method");
}

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SilhouetteOptions, source, background_blur_sigma, background_threshold,
                                   background_method, background_open_radius, background_min_threshold,
                                   background_contour_fraction, background_shadow_test, shadow_min_gain,
                                   shadow_max_gain, shadow_window_radius, background_noise_factor,
                                   working_volume_margin, min_background_fraction, motion_sigma, motion_lambda, motion_window,
                                   motion_threshold, motion_method, motion_min_threshold, estimate_background,
                                   background_estimate_min_frames, background_estimate_margin, close_radius, background_close_floor, background_outlines,
                                   fill_holes, min_region_pixels, min_object_pixels)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(StandingEvidenceOptions, enabled, noise_factor, min_threshold)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(PlaneSweepOptions, neighbours, max_neighbour_degrees, consistent_views,
                                   window_radius, max_step_pixels, max_planes, sweep_beyond_volume, min_score,
                                   min_texture, uniqueness_margin, uniqueness_planes, threads)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(DepthFusionOptions, consistent_cameras, consistency_planes,
                                   unconfirmed_min_score, free_space_planes, free_votes, min_hits, min_cameras,
                                   min_component_fraction)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SupportPlaneOptions, tolerance, iterations, sample_points, min_inlier_fraction,
                                   min_above_fraction, seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(PlainBackdropOptions, enabled, border_fraction, spread_quantile, max_spread)
// WITH_DEFAULT: options files written before `backdrop` existed (2026-12-06) still load.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(StillEvidenceOptions, enabled, backdrop, sweep, fusion,
                                                remove_support_plane, support_plane, support_tolerance_planes)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(ConcavityCarvingOptions, enabled, every_frame, sweep, fusion, min_neighbours,
                                   pixels_per_voxel, surface_margin_voxels, surface_veto, opening_radius, min_depth,
                                   max_carved_fraction,
                                   min_component_fraction)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(VoxelCarvingOptions, resolution, pixels_per_voxel, max_auto_resolution,
                                   max_pixels_per_voxel,
                                   min_cameras, max_misses, evidence_threshold, footprint_margin, closing_radius,
                                   opening_radius, connectivity, min_component_fraction, fill_cavities,
                                   compute_silhouette_iou, threads)

}  // namespace subflow::vision

namespace subflow::geometry {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(IsosurfaceOptions, iso_value, smoothing_sigma_voxels, padding_voxels,
                                   facet_angle_degrees, facet_size_voxels, facet_distance_voxels,
                                   max_vertex_count, random_seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SimplifyOptions, target_face_count, max_distance, min_face_count,
                                   max_face_count, max_normal_change_degrees,
                                   min_triangle_angle_degrees, max_valence, min_valence, flip_rounds,
                                   max_flip_dihedral_degrees, check_self_intersections, max_attempts, retry_growth)

}  // namespace subflow::geometry

namespace subflow::solver {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(HierarchyFitOptions, iterations_per_level, max_snap_distance)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SurfaceRegistrationOptions, enabled, iterations, stiffness_start, stiffness_end,
                                   point_weight, max_distance_edges, min_normal_cosine, min_start_distance_edges)
// WITH_DEFAULT: options files written before `concavities` existed still load.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ShapeInitOptions, silhouettes, standing, still, carving, concavities,
                                   isosurface, simplify, registration, fit, base_distance_voxels, levels, finest_edge_pixels, max_finest_faces,
                                   reference_frame, first_frame, frame_count, image_edge_pixels)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(SurfaceSamplingOptions, samples_per_pixel, max_density)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE(VisibilityOptions, depth_tolerance, min_view_cosine, image_margin,
                                   tessellation_density)
// WITH_DEFAULT: options files written before the newest fields existed still load (those
// fields then take their defaults).
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(NormalFlowSolverOptions, smoothness, rigid_invariant_smoothness,
                                                detail_damping, coarsest_level, finest_level, min_samples_per_face,
                                                reweighting_iterations, robust_threshold, noise_floor,
                                                collinearity_pruning, collinearity_min_cameras, cg_tolerance,
                                                cg_reweighting_tolerance, cg_max_iterations, multigrid,
                                                multigrid_min_vertices)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MotionStepOptions, sampling, visibility, solver, image_sigmas,
                                                highpass_sigma, first_highpass_sigma)
// "off", "auto", "on". Option files written while it was a bool hold true / false: read as
// "on" / "off", as those runs did (a file without the key takes the default, "auto").
inline void to_json(nlohmann::json& json, ConcurrentHalves mode) { json = ToString(mode); }
inline void from_json(const nlohmann::json& json, ConcurrentHalves& mode) {
  if (json.is_boolean()) mode = json.get<bool>() ? ConcurrentHalves::kOn : ConcurrentHalves::kOff;
  else if (json.is_string()) mode = ParseConcurrentHalves(json.get<std::string>(), "concurrent_halves");
  else ThrowError("options", "concurrent_halves", "expected \"auto\", \"on\" or \"off\", got " + json.dump());
}
// WITH_DEFAULT below too.
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MotionInitOptions, step, hull_weight, hull_max_distance,
                                                hull_iterations, registration, guess_from_targets,
                                                guess_previous_step, spread_registration, registration_min_unreached,
                                                concurrent_chains)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(WindowSolverOptions, linear_solver, max_iterations, threads,
                                                function_tolerance, iterative_from_unknowns, iterative_solver,
                                                iterative_eta, reduced_correlation_blocks)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(StereoRefinementOptions, coarsest_level, finest_level, min_patch_area,
                                   per_patch_levels, detail_threshold, min_detail_patch_area,
                                   normal_only_from_level, tangential_only_at_outlines, slide_coherence, window, window_overlap, concurrent_halves, rounds, solver,
                                   samples_per_pixel, min_density, max_density, max_cameras, min_samples,
                                   image_sigma, ncc_epsilon, ncc_loss_scale, temporal_weight, silhouette_weight,
                                   silhouette_from_level, rim_band, angle_weight_power, outline_margin, membrane_weight, temporal_smoothness,
                                   damping, max_step, adaptive_threshold, visibility)

// The stages under the names of their report sections.
inline void to_json(nlohmann::json& json, const ReconstructionOptions& options) {
  json = {{"shape_init", options.shape},   {"motion_init", options.motion},
          {"refinement", options.refinement}, {"refine", options.refine},
          {"retrack", options.retrack},    {"retrack_weight", options.retrack_weight},
          {"retrack_highpass", options.retrack_highpass}, {"retrack_register", options.retrack_register}};
}
inline void from_json(const nlohmann::json& json, ReconstructionOptions& options) {
  json.at("shape_init").get_to(options.shape);
  json.at("motion_init").get_to(options.motion);
  json.at("refinement").get_to(options.refinement);
  json.at("refine").get_to(options.refine);
  json.at("retrack").get_to(options.retrack);
  json.at("retrack_weight").get_to(options.retrack_weight);
  // Options files written before the retrack had its own high-pass have none: their retrack
  // ran on the first pass's (motion_init.step.highpass_sigma), and still does.
  options.retrack_highpass = json.value("retrack_highpass", options.motion.step.highpass_sigma);
  // Those written before the retrack registered lost frames (2026-12-06) did not.
  options.retrack_register = json.value("retrack_register", false);
  // Those written before the motion passes tried the previous step as a start (2026-12-07)
  // did not.
  options.motion.guess_previous_step = json.at("motion_init").value("guess_previous_step", false);
  // Those written before the sliding vertices were tied over the frames (2026-12-08) were
  // not.
  options.refinement.slide_coherence = json.at("refinement").value("slide_coherence", 0.0);
}

}  // namespace subflow::solver
