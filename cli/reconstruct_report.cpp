#include "cli/reconstruct_report.h"

#include "cli/stage_options.h"

#include <cmath>

namespace subflow::cli {
namespace {

nlohmann::json Vector3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

nlohmann::json MotionInitJson(const solver::MotionInitOptions& o, const solver::MotionInitResult& result,
                              int first_frame) {
  nlohmann::json frames = nlohmann::json::array();
  for (const solver::MotionFrameReport& f : result.frames) {
    frames.push_back({{"frame", first_frame + f.frame},
                      {"from_frame", f.from_frame < 0 ? -1 : first_frame + f.from_frame},
                      {"constraints", f.step.constraints},
                      {"pruned", f.step.pruned},
                      {"collinearity_pruned", f.step.collinearity_pruned},
                      {"photometric_rms_zero_motion", f.step.photometric_rms_zero},
                      {"photometric_rms", f.step.photometric_rms},
                      {"mean_displacement", f.step.mean_displacement},
                      {"cg_iterations", f.step.cg_iterations},
                      {"corrected", f.corrected},
                      {"correction_rms_before", f.correction_rms_before},
                      {"correction_rms_after", f.correction_rms_after},
                      {"seconds", f.step.seconds}});
  }
  return {{"options",
           {{"image_sigmas", o.step.image_sigmas},
            {"samples_per_pixel", o.step.sampling.samples_per_pixel},
            {"smoothness", o.step.solver.smoothness},
            {"detail_damping", o.step.solver.detail_damping},
            {"reweighting_iterations", o.step.solver.reweighting_iterations},
            {"collinearity_pruning", o.step.solver.collinearity_pruning},
            {"hull_weight", o.hull_weight},
            {"hull_max_distance", o.hull_max_distance},
            {"hull_iterations", o.hull_iterations}}},
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
                      {"windows", l.windows},
                      {"parameters", l.parameters}, {"residual_blocks", l.residual_blocks},
                      {"mean_increment", l.mean_increment}, {"iterations", l.iterations},
                      {"seconds", l.seconds}, {"solver_seconds", l.solver_seconds}});
  nlohmann::json frames = nlohmann::json::array();
  for (const solver::RefinementFrameReport& f : result.frames)
    frames.push_back({{"frame", first_frame + f.frame}, {"stereo_pairs", f.stereo_pairs},
                      {"ncc_before", f.ncc_before}, {"ncc_after", f.ncc_after},
                      {"silhouette_rms_px_before", f.silhouette_rms_before},
                      {"silhouette_rms_px_after", f.silhouette_rms_after}});
  return {{"options",
           {{"coarsest_level", o.coarsest_level}, {"finest_level", o.finest_level},
            {"normal_only_from_level", o.normal_only_from_level}, {"window", o.window},
            {"window_overlap", o.window_overlap},
            {"rounds", o.rounds}, {"max_iterations", o.solver.max_iterations},
            {"linear_solver", LinearSolverName(o.solver.linear_solver)}, {"threads", o.solver.threads},
            {"samples_per_pixel", o.samples_per_pixel}, {"min_density", o.min_density},
            {"max_density", o.max_density}, {"max_cameras", o.max_cameras},
            {"min_samples", o.min_samples}, {"image_sigma", o.image_sigma},
            {"ncc_epsilon", o.ncc_epsilon}, {"ncc_loss_scale", o.ncc_loss_scale},
            {"temporal_weight", o.temporal_weight}, {"silhouette_weight", o.silhouette_weight},
            {"angle_weight_power", o.angle_weight_power}, {"outline_margin", o.outline_margin}, {"membrane_weight", o.membrane_weight},
            {"temporal_smoothness", o.temporal_smoothness}, {"damping", o.damping},
            {"max_step", o.max_step}, {"adaptive_threshold", o.adaptive_threshold}}},
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

}  // namespace subflow::cli
