#include "cli/stage_options.h"

#include <algorithm>

#include "output/options_json.h"

namespace subflow::cli {

void AddDatasetAndOutput(CLI::App* sub, std::string* dataset, std::string* out, bool* overwrite) {
  sub->add_option("DATASET", *dataset, "Dataset directory (../shared/DATASET.md)")
      ->required()->check(CLI::ExistingDirectory);
  sub->add_option("--out", *out, "Output directory (must be new or empty)")->required();
  sub->add_flag("--overwrite", *overwrite, "Write into a non-empty output directory");
}

void AddFramesOption(CLI::App* sub, int* first, int* count, bool allow_count) {
  sub->add_option_function<std::string>(
         "--frames",
         [first, count, allow_count](const std::string& text) {
           const std::size_t colon = text.find(':');
           try {
             std::size_t used = 0;
             if (colon == std::string::npos && allow_count) {
               *count = std::stoi(text, &used);
               if (used == text.size() && (*count > 0 || *count == -1)) return;
             } else if (colon != std::string::npos) {
               const int a = std::stoi(text.substr(0, colon), &used);
               const bool whole_a = used == colon;
               const int b = std::stoi(text.substr(colon + 1), &used);
               if (whole_a && used == text.size() - colon - 1 && a >= 0 && b > a) {
                 *first = a;
                 *count = b - a;
                 return;
               }
             }
           } catch (const std::exception&) {
           }
           throw CLI::ValidationError("--frames", "'" + text + "': expected A:B (frames A to B - 1, 0 <= A < B)" +
                                                     std::string(allow_count ? " or a frame count N" : ""));
         },
         allow_count ? "Frames A:B (A to B - 1), or a count N from --first-frame (-1 = to the end)"
                     : "Frames A:B (A to B - 1) of the input stage folder to run on (default: all)")
      ->type_name(allow_count ? "A:B|N" : "A:B");
}

void AddShapeInitOptions(CLI::App* sub, solver::ShapeInitOptions* o, std::string* evidence) {
  sub->add_option("--evidence", *evidence,
                  "Object evidence: auto (masks, else background, else motion (with what stands still), else "
                  "still: the reference frame against a plain backdrop, else its photo-consistency), mask, "
                  "background, motion, still")
      ->capture_default_str();
  sub->add_option("--levels", o->levels,
                  "Subdivision levels above the base mesh (-1 = automatic: finest edges about "
                  "--finest-edge-pixels where the subject is smooth)")
      ->capture_default_str()->check(CLI::Range(-1, 6));
  sub->add_option("--finest-edge-pixels", o->finest_edge_pixels,
                  "Projected length of the finest level's edges the automatic levels aim at, in [0.25, 1000]")
      ->capture_default_str()->check(CLI::Range(0.25, 1000.0));
  sub->add_option("--max-finest-faces", o->max_finest_faces,
                  "Face budget of the automatic levels' finest level (motion and refinement cost grows with it)")
      ->capture_default_str()->check(CLI::Range(4, 50000000));
  sub->add_option("--base-distance", o->base_distance_voxels,
                  "The base mesh T0 stays within this many voxels of the reference hull, both ways: the "
                  "subject's detail sets its faces (0 = by count, --base-faces)")
      ->capture_default_str()->check(CLI::Range(0.0, 100.0));
  sub->add_option_function<int>(
         "--base-faces",
         [o](int faces) {
           o->simplify.target_face_count = faces;
           o->base_distance_voxels = 0;
         },
         "Faces of the base mesh T0, by count instead of the distance bound (--base-distance 0)")
      ->default_str(std::to_string(o->simplify.target_face_count))->check(CLI::Range(4, 100000000));
  sub->add_option("--reference-frame", o->reference_frame,
                  "Frame giving the base connectivity (-1 = middle frame)")->capture_default_str();
  sub->add_option("--first-frame", o->first_frame, "First frame to process")->capture_default_str();
  AddFramesOption(sub, &o->first_frame, &o->frame_count, true);
  sub->add_option("--resolution", o->carving.resolution,
                  "Voxels along the longest axis of the working volume (0 = automatic, ~2 px per voxel)")
      ->capture_default_str();
  sub->add_option("--min-cameras", o->carving.min_cameras,
                  "Cameras that must see and support a voxel (at least 1)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  sub->add_option("--max-misses", o->carving.max_misses,
                  "Cameras that see a voxel without supporting it, tolerated before it is carved "
                  "(-1 = automatic: 0 for masks and background differences, 1 when motion evidence is used)")
      ->capture_default_str()->check(CLI::Range(-1, 1000));
  sub->add_option("--evidence-threshold", o->carving.evidence_threshold,
                  "Fraction of a voxel's footprint that must be object for a camera to support it, "
                  "in (0, 1]; small = conservative hull")
      ->capture_default_str()->check(CLI::Range(1e-6, 1.0));
  sub->add_option("--footprint-margin", o->carving.footprint_margin,
                  "Pixels added on each side of a voxel's footprint for its evidence, in [0, 100]")
      ->capture_default_str()->check(CLI::Range(0.0, 100.0));
  sub->add_option("--lambda", o->silhouettes.motion_lambda, "λ of the motion evidence (eq. 23), > 0")
      ->capture_default_str()->check(CLI::PositiveNumber);
  sub->add_option("--motion-window", o->silhouettes.motion_window,
                  "Half-width of the frame window over which motion evidence is accumulated")
      ->capture_default_str()->check(CLI::Range(0, 100));
  sub->add_option("--motion-threshold", o->silhouettes.motion_threshold,
                  "Threshold of the motion evidence (< 0 = automatic, Otsu)")->capture_default_str();
  sub->add_option("--background-threshold", o->silhouettes.background_threshold,
                  "Threshold of the background difference, below 1 (< 0 = automatic: per camera from the noise "
                  "outside the working volume, else triangle)")
      ->capture_default_str()->check(CLI::Range(-1e9, 0.999999));
  sub->add_option("--background-noise-factor", o->silhouettes.background_noise_factor,
                  "Automatic background threshold: the camera's median difference outside the working volume "
                  "plus this many robust sigmas, in (0, 100]")
      ->capture_default_str()->check(CLI::Range(1e-6, 100.0));
  sub->add_flag("!--no-shadow-test", o->silhouettes.background_shadow_test,
                "Background difference without the shadow test (a darkening that keeps the background's "
                "texture then counts as object)");
  sub->add_flag("--concavities", o->concavities.enabled,
                "Carve every frame's visual hull where the images see through it (hollows no silhouette reaches; "
                "vision/concavity_carving.h; off by default, see docs/shape.md)");
}

void AddMotionInitOptions(CLI::App* sub, solver::MotionInitOptions* o, bool first_pass) {
  sub->add_option("--motion-smoothness", o->step.solver.smoothness,
                  "Smoothness weight of the normal-flow solver (aperture problem)")->capture_default_str();
  sub->add_flag_callback(
      "--no-velocity-guess", [o] { o->guess_previous_step = false; },
      "Motion passes: do not try the previous step (a constant velocity) as a step's start; each step starts at "
      "zero motion (or, in the retrack, at the refined surface when that matches the images better)");
  if (!first_pass) return;  // the retrack's are --retrack-highpass and --retrack-weight
  sub->add_option("--motion-highpass", o->step.highpass_sigma,
                  "First motion pass on the log intensities minus their blur of this sigma (pixels): gain "
                  "and shading removed, texture kept (0 = the raw intensities)")
      ->check(CLI::Range(0.0, solver::kMaxHighPassSigma))
      ->capture_default_str();
  sub->add_option("--hull-weight", o->hull_weight,
                  "Blend of the per-frame normal correction towards the frame's hull fit (0 = off)")
      ->capture_default_str();
}

namespace {

// Option `name`: a ceres::LinearSolverType by Ceres's name (any case) into `*type`, whose
// value is the default shown; a name Ceres does not know is refused, naming `examples`.
void AddLinearSolverOption(CLI::App* sub, const std::string& name, ceres::LinearSolverType* type,
                           const std::string& examples, const std::string& description) {
  sub->add_option_function<std::string>(
         name,
         [name, type, examples](const std::string& value) {
           if (!ceres::StringToLinearSolverType(value, type))
             throw CLI::ValidationError(name, "'" + value + "' is not a Ceres linear solver type (e.g. " +
                                                  examples + ")");
         },
         description)
      ->default_str(nlohmann::json(*type).get<std::string>());
}

}  // namespace

void AddRefinementOptions(CLI::App* sub, solver::StereoRefinementOptions* o) {
  sub->add_option("--refine-from", o->coarsest_level, "Coarsest level refined by stereo")
      ->capture_default_str();
  sub->add_option("--refine-to", o->finest_level,
                  "Finest level refined by stereo (-1 = one below the finest level)")->capture_default_str();
  sub->add_option("--window", o->window, "Frames refined jointly")->capture_default_str();
  sub->add_option("--window-overlap", o->window_overlap,
                  "Frames a window shares with the next one, solved again there (at most --window - 1)")
      ->capture_default_str();
  sub->add_option_function<std::string>(
         "--concurrent-halves",
         [o](const std::string& text) {
           o->concurrent_halves = solver::ParseConcurrentHalves(text, "--concurrent-halves");
         },
         "auto|on|off: refine a take of at least 3 windows as two halves side by side, then a window across the "
         "seam; auto = at the levels whose windows go to the iterative solver (faster there, more memory; "
         "docs/speed.md). Default: auto")
      ->check(CLI::IsMember({"auto", "on", "off"}));
  sub->add_option("--rounds", o->rounds, "Visibility updates per level")->capture_default_str();
  sub->add_option("--iterations", o->solver.max_iterations, "Ceres iterations per window and round")
      ->capture_default_str();
  sub->add_option("--function-tolerance", o->solver.function_tolerance,
                  "A window's solve ends when an iteration lowers the cost by less than this fraction")
      ->capture_default_str();
  AddLinearSolverOption(sub, "--linear-solver", &o->solver.linear_solver,
                        "sparse_normal_cholesky, sparse_schur, iterative_schur, cgnr, dense_qr",
                        "Ceres linear solver type (ceres::LinearSolverType, any case)");
  sub->add_option("--iterative-from-unknowns", o->solver.iterative_from_unknowns,
                  "Windows with at least this many vertex blocks (frames x vertices) use --iterative-solver instead (0 = never)")
      ->capture_default_str();
  AddLinearSolverOption(sub, "--iterative-solver", &o->solver.iterative_solver, "cgnr, iterative_schur",
                        "Ceres linear solver of the large windows (ceres::LinearSolverType, any case)");
  sub->add_option("--threads", o->solver.threads, "Ceres threads (0 = all cores)")->capture_default_str();
  sub->add_option("--samples-per-pixel", o->samples_per_pixel,
                  "Surface samples per pixel² of a patch's finest view")->capture_default_str();
  sub->add_option("--max-cameras", o->max_cameras, "Best-facing cameras paired per patch")
      ->capture_default_str();
  sub->add_option("--temporal-weight", o->temporal_weight,
                  "Weight of the temporal self-correlation (motion along the surface)")->capture_default_str();
  sub->add_option("--silhouette-weight", o->silhouette_weight, "Weight of the outline term per pixel")
      ->capture_default_str();
  sub->add_flag_callback(
      "--slide-at-outlines",
      [o] {
        o->normal_only_from_level = std::max(o->normal_only_from_level, 1);
        o->tangential_only_at_outlines = true;
      },
      "Base level: vertices at measured outlines (masks, a plain backdrop, a background image) may also slide along "
      "the surface (1-8 % more accurate on the scenes; the refinement 1.5-2.5x slower)");
  sub->add_option("--slide-coherence", o->slide_coherence,
                  "Where vertices slide: weight of the first difference of their sliding over the frames")
      ->capture_default_str();
  sub->add_option("--silhouette-from-level", o->silhouette_from_level,
                  "Coarsest level with outline blocks (a base-level block drags a wide region)")->capture_default_str();
  sub->add_option("--rim-band", o->rim_band,
                  "Draw the surface's rim onto mask outlines it lies within this many pixels of (0 = off)")
      ->capture_default_str();
  sub->add_option("--membrane-weight", o->membrane_weight, "Spatial smoothness of the corrections")
      ->capture_default_str();
  sub->add_option("--temporal-smoothness", o->temporal_smoothness,
                  "Temporal smoothness of the corrections")->capture_default_str();
}

solver::ReconstructionOptions ReconstructionArguments::Options() const {
  solver::ReconstructionOptions result = options;
  result.shape.silhouettes.source = vision::ParseEvidenceSource(evidence, "--evidence");
  result.refine = !no_refine;
  result.Check();
  return result;
}

void AddRetrackOptions(CLI::App* sub, solver::ReconstructionOptions* o) {
  sub->add_option("--retrack-weight", o->retrack_weight,
                  "Blend of the second motion pass towards each frame's refined surface (0..1)")
      ->capture_default_str();
  sub->add_option("--retrack-highpass", o->retrack_highpass,
                  "Second motion pass on the log intensities minus their blur of this sigma (pixels): gain "
                  "and shading removed, texture kept (0 = the raw intensities)")
      ->check(CLI::Range(0.0, solver::kMaxHighPassSigma))
      ->capture_default_str();
  sub->add_flag("!--no-retrack-register", o->retrack_register,
                "Do not register the second motion pass's frames that lost their refined surface (more than a "
                "quarter of it out of reach, e.g. a limb left behind): snap only");
}

void AddReconstructionOptions(CLI::App* sub, ReconstructionArguments* arguments) {
  sub->add_flag("--no-refine", arguments->no_refine,
                "Stop after motion initialization (no spatio-temporal stereo refinement)");
  sub->add_flag("!--no-retrack", arguments->options.retrack,
                "Keep the first motion pass (do not re-estimate trajectories on the refined shapes)");
  AddRetrackOptions(sub, &arguments->options);
  AddShapeInitOptions(sub, &arguments->options.shape, &arguments->evidence);
  AddMotionInitOptions(sub, &arguments->options.motion);
  AddRefinementOptions(sub, &arguments->options.refinement);
}

}  // namespace subflow::cli
