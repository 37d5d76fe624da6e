#include "solver/stereo/stereo_refinement.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include <Eigen/Geometry>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "core/task_errors.h"
#include "geometry/multires_shape.h"
#include "solver/stereo/patch_levels.h"
#include "solver/stereo/refinement_window.h"
#include "solver/stereo/window_solve.h"

namespace subflow::solver {
namespace {

using geometry::LoopHierarchy;
using geometry::Positions;

// The frame ranges [w0, w1] of the windows over `frames` frames: `window` frames each
// (fewer at the end), consecutive ones sharing min(overlap, window − 1) frames.
std::vector<std::pair<int, int>> Windows(int frames, int window, int overlap) {
  std::vector<std::pair<int, int>> windows;
  const int step = window - std::min(overlap, window - 1);
  for (int w0 = 0;; w0 += step) {
    const int w1 = std::min(frames - 1, w0 + window - 1);
    windows.emplace_back(w0, w1);
    if (w1 == frames - 1) break;
  }
  return windows;
}

// A chain of windows solved one after another, reading only frames [span_first, span_last].
struct WindowChain {
  int span_first = 0, span_last = 0;
  std::vector<std::pair<int, int>> windows;
};

// A level's windows: one chain over the take; or, with `halves` on a take of at least 3
// windows, the two halves' chains side by side (neither reads a frame of the other), then
// one window across the seam whose context is both halves' refined frames.
struct WindowPlan {
  std::vector<WindowChain> halves;
  WindowChain seam;  // no window without halves

  std::size_t Count() const {
    std::size_t count = seam.windows.size();
    for (const WindowChain& half : halves) count += half.windows.size();
    return count;
  }
};

WindowPlan PlanWindows(int frames, const StereoRefinementOptions& options, bool halves) {
  auto chain = [&](int first, int last) {
    WindowChain result{first, last, Windows(last - first + 1, options.window, options.window_overlap)};
    for (auto& [w0, w1] : result.windows) w0 += first, w1 += first;
    return result;
  };
  WindowPlan plan;
  if (!halves || frames < 3 * options.window) {
    plan.halves.push_back(chain(0, frames - 1));
    return plan;
  }
  const int middle = frames / 2, first = middle - options.window / 2;
  plan.halves = {chain(0, middle - 1), chain(middle, frames - 1)};
  plan.seam = {0, frames - 1, {{first, first + options.window - 1}}};
  return plan;
}

// Whether the windows of `level` run as two halves side by side (concurrent_halves): kAuto
// when a window of the level (its frames × the active patches' corners: vertex blocks)
// goes to the iterative solver, whose products run on one thread.
bool SideBySide(const StereoRefinementOptions& options, const RefinementLevel& level, int frames) {
  if (options.concurrent_halves != ConcurrentHalves::kAuto) return options.concurrent_halves == ConcurrentHalves::kOn;
  const std::int64_t vertices = std::count(level.active_vertices.begin(), level.active_vertices.end(), 1);
  const std::int64_t blocks = vertices * std::min(options.window, frames);
  return options.solver.Iterative(static_cast<int>(std::min<std::int64_t>(blocks, std::numeric_limits<int>::max())));
}

// The refinement state of the whole sequence, which the windows' solutions move.
struct SequenceState {
  geometry::Trajectory trajectory;
  RefinementResult* result;  // control (finest control points) and the per-frame figures
};

// Adds a window's solution to the shapes of its frames (base control points at level 0,
// details in their local frames above), re-synthesizes their finest control points and
// records the figures; `moved` keeps the largest world displacement of every vertex.
void ApplySolution(const LoopHierarchy& hierarchy, int level, const WindowSolution& solution,
                   SequenceState* state, std::vector<double>* moved) {
  const int finest = hierarchy.finest_level();
  for (int t = solution.first; t <= solution.last; ++t) {
    const int i = t - solution.first;
    const WindowSolution::Increments& e = solution.increments[i];
    const Positions& world = solution.displacement[i];
    geometry::MultiresShape& shape = state->trajectory[t];
    Positions& target = level == 0 ? shape.base() : shape.Detail(level);
    for (Eigen::Index v = 0; v < world.rows(); ++v) {
      const Eigen::Vector3d displacement = world.row(v).transpose();
      (*moved)[v] = std::max((*moved)[v], displacement.norm());
      if (level == 0) {
        target.row(v) += displacement.transpose();
      } else {
        for (Eigen::Index d = 0; d < e.cols(); ++d) target(v, d) += e(v, d);  // local (n, r, q)
      }
    }
    state->result->control[t] = shape.Synthesize(hierarchy, finest);

    const WindowFrameFigures& figures = solution.frames[i];
    RefinementFrameReport& report = state->result->frames[t];
    if (report.stereo_pairs == 0 && figures.stereo_pairs > 0) {  // first time this frame is refined
      report.ncc_before = figures.ncc_before;
      report.silhouette_rms_before = figures.silhouette_rms_before;
    }
    if (figures.stereo_pairs > 0) {
      report.stereo_pairs = figures.stereo_pairs;
      report.ncc_after = figures.ncc_after;
      report.silhouette_rms_after = figures.silhouette_rms_after;
    }
  }
}

// What the windows of one chain add up to over a round (the level's report sums them).
struct ChainTally {
  int parameters = 0, residual_blocks = 0, iterative_windows = 0, iterations = 0;
  double solver_seconds = 0;
};

// Refines level ℓ over all frames, window by window (PlanWindows), `rounds` times; returns
// the vertices of ℓ that moved by more than the adaptive threshold (the next level's
// active patches). caches[i]: the frames of half i (the seam's with the first half's).
std::vector<char> RefineLevel(const vision::ImageSequence& images, const LoopHierarchy& hierarchy,
                              const vision::Bounds& bounds, const StereoRefinementOptions& options,
                              int level, std::vector<char> active_faces, FrameImageCache* const caches[2],
                              SequenceState* state, Progress* progress, std::size_t* progress_done) {
  const Stopwatch start;
  RefinementLevel prepared =
      PrepareLevel(hierarchy, images.cameras, options, state->trajectory, level, std::move(active_faces));
  // Sliding only at measured outlines, and none is measured (every silhouette a projected
  // hull, or none): every vertex would be held to its normal, so the level keeps dof 1 (the
  // same unknowns, a third of the Jacobian's columns).
  const bool outlines_measured =
      images.silhouette && (images.tight_outline.empty() ||
                            std::any_of(images.tight_outline.begin(), images.tight_outline.end(),
                                        [](char tight) { return tight != 0; }));
  if (prepared.dof == 3 && options.tangential_only_at_outlines && !outlines_measured) prepared.dof = 1;
  RefinementLevelReport report;
  report.level = level;
  report.dof = prepared.dof;
  report.patches = hierarchy.FaceCount(level);
  report.active_patches = static_cast<int>(std::count(prepared.active_faces.begin(), prepared.active_faces.end(), 1));
  report.active_fraction = static_cast<double>(report.active_patches) / report.patches;
  const int frames = static_cast<int>(state->result->control.size());
  const WindowPlan plan = PlanWindows(frames, options, SideBySide(options, prepared, frames));
  report.windows = static_cast<int>(plan.Count());
  report.concurrent_halves = plan.halves.size() > 1;
  // Per half: the largest displacement of every vertex (the halves write different frames).
  std::vector<std::vector<double>> moved(plan.halves.size(), std::vector<double>(hierarchy.VertexCount(level), 0.0));
  std::mutex progress_mutex;
  // A chain of windows; beside the other half's (`group`), it stops early once that has thrown.
  auto run = [&](const WindowChain& chain, FrameImageCache* cache, std::vector<double>* chain_moved,
                 ChainTally* tally, const TaskErrors* group) {
    for (std::size_t w = 0; w < chain.windows.size() && !(group && group->failed()); ++w) {
      const auto [first, last] = chain.windows[w];
      RefinementWindow window = OpenWindow(prepared, hierarchy, images.cameras, options, state->trajectory,
                                           state->result->control, cache, first, last, chain.span_first,
                                           chain.span_last);
      const WindowSolution solution = SolveWindow(window, bounds);
      tally->parameters += solution.parameters;
      tally->residual_blocks += solution.residual_blocks;
      tally->iterative_windows += solution.iterative;
      tally->iterations += solution.iterations;
      tally->solver_seconds += solution.solver_seconds;
      ApplySolution(hierarchy, level, solution, state, chain_moved);
      // The next window needs its frames and its context frame before them.
      if (w + 1 < chain.windows.size()) cache->Release(chain.windows[w + 1].first - 1);
      const std::lock_guard<std::mutex> lock(progress_mutex);
      ProgressUpdate(progress, ++*progress_done);
    }
  };
  for (int round = 0; round < options.rounds; ++round) {
    std::vector<ChainTally> tallies(plan.halves.size());
    for (std::size_t i = 0; i < plan.halves.size(); ++i) {
      caches[i]->ForgetVisibility();  // another level's samples, or another round
      // A level after one run the other way: the frames a cache kept from it that its half
      // will not read (one chain's last window, in the first half's cache).
      caches[i]->Release(plan.halves[i].span_first, plan.halves[i].span_last);
    }
    if (plan.halves.size() == 1) {
      run(plan.halves[0], caches[0], &moved[0], &tallies[0], nullptr);
    } else {
      RunSideBySide(  // core/task_errors.h
          [&](const TaskErrors& group) { run(plan.halves[0], caches[0], &moved[0], &tallies[0], &group); },
          [&](const TaskErrors& group) { run(plan.halves[1], caches[1], &moved[1], &tallies[1], &group); });
      run(plan.seam, caches[0], &moved[0], &tallies[0], nullptr);
    }
    report.parameters = report.residual_blocks = report.iterative_windows = 0;  // the last round's
    for (const ChainTally& tally : tallies) {
      report.parameters += tally.parameters;
      report.residual_blocks += tally.residual_blocks;
      report.iterative_windows += tally.iterative_windows;
      report.iterations += tally.iterations;
      report.solver_seconds += tally.solver_seconds;
    }
  }
  for (std::size_t i = 1; i < moved.size(); ++i)
    for (std::size_t v = 0; v < moved[0].size(); ++v) moved[0][v] = std::max(moved[0][v], moved[i][v]);
  double moved_sum = 0.0;
  std::vector<char> moved_vertices(moved[0].size(), 0);  // 0: still, 1: moved, 2: moved a lot
  for (std::size_t v = 0; v < moved[0].size(); ++v) {
    const double distance = moved[0][v];
    moved_sum += distance;
    if (distance > options.adaptive_threshold * prepared.h) moved_vertices[v] = 1;
    if (options.detail_threshold > 0.0 && distance > options.detail_threshold * prepared.h) moved_vertices[v] = 2;
  }
  report.mean_increment = moved_sum / static_cast<double>(moved_vertices.size());
  report.seconds = start.Seconds();
  spdlog::info("refinement level {}: {} of {} patches, dof {}, {} unknowns, {} residual blocks, "
               "{} iterations, mean max |increment| {:.3g}, {:.1f} s ({:.1f} s in Ceres){}",
               level, report.active_patches, report.patches, report.dof, report.parameters,
               report.residual_blocks, report.iterations, report.mean_increment, report.seconds,
               report.solver_seconds, report.concurrent_halves ? ", two halves side by side" : "");
  state->result->levels.push_back(report);
  return moved_vertices;
}

}  // namespace

std::string ToString(ConcurrentHalves mode) {
  switch (mode) {
    case ConcurrentHalves::kOff: return "off";
    case ConcurrentHalves::kAuto: return "auto";
    case ConcurrentHalves::kOn: return "on";
  }
  return "?";
}

ConcurrentHalves ParseConcurrentHalves(const std::string& text, const std::string& field) {
  for (ConcurrentHalves mode : {ConcurrentHalves::kOff, ConcurrentHalves::kAuto, ConcurrentHalves::kOn})
    if (ToString(mode) == text) return mode;
  ThrowError("stereo refinement options", field, "'" + text + "' is not one of off, auto, on");
}

std::string RefinementResult::BriefReport() const {
  std::string level_list;
  int iterations = 0;
  double solver_seconds = 0;
  for (const RefinementLevelReport& level : levels) {
    level_list += fmt::format("{}{} ({:.0f} %)", level_list.empty() ? "" : ", ", level.level, 100 * level.active_fraction);
    iterations += level.iterations;
    solver_seconds += level.solver_seconds;
  }
  double before = 0, after = 0;
  int refined = 0;
  for (const RefinementFrameReport& frame : frames)
    if (frame.stereo_pairs > 0) before += frame.ncc_before, after += frame.ncc_after, ++refined;
  return fmt::format("refinement: levels {}, {} Ceres iterations, mean NCC {:.4f} → {:.4f} over {} frames, "
                     "{:.1f} s ({:.1f} s in Ceres)",
                     level_list, iterations, refined ? before / refined : 0.0, refined ? after / refined : 0.0,
                     refined, seconds, solver_seconds);
}

void WindowSolverOptions::Check() const {
  if (max_iterations < 1) ThrowError("stereo refinement options", "solver.max_iterations", "must be ≥ 1");
  if (threads < 0) ThrowError("stereo refinement options", "solver.threads", "must be ≥ 0 (0 = all cores)");
  if (!(function_tolerance > 0)) ThrowError("stereo refinement options", "solver.function_tolerance", "must be > 0");
  if (!(iterative_eta > 0 && iterative_eta < 1))
    ThrowError("stereo refinement options", "solver.iterative_eta", "must be in (0, 1)");
  if (iterative_from_unknowns < 0)
    ThrowError("stereo refinement options", "solver.iterative_from_unknowns", "must be ≥ 0 (0 = never)");
  std::string why;
  if (!ToCeres().IsValid(&why)) ThrowError("stereo refinement options", "solver", why);
  if (iterative_from_unknowns > 0 && !ToCeres(iterative_from_unknowns).IsValid(&why))
    ThrowError("stereo refinement options", "solver.iterative_solver", why);
}

bool WindowSolverOptions::Iterative(int vertex_blocks) const {
  return iterative_from_unknowns > 0 && vertex_blocks >= iterative_from_unknowns;
}

ceres::Solver::Options WindowSolverOptions::ToCeres(int vertex_blocks) const {
  ceres::Solver::Options options;
  const bool iterative = Iterative(vertex_blocks);
  options.linear_solver_type = iterative ? iterative_solver : linear_solver;
  if (iterative) options.eta = iterative_eta;
  options.max_num_iterations = max_iterations;
  options.num_threads = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  options.minimizer_progress_to_stdout = false;
  options.logging_type = ceres::SILENT;
  options.function_tolerance = function_tolerance;
  // With bounds (the step bounds) Ceres's trust-region minimizer runs a projected Armijo
  // line search on every step, whose first trial evaluates the cost at the full projected
  // step: the very point the candidate evaluation computes next (one whole residual
  // evaluation in two per iteration; Ceres's own comment calls the search "not terribly
  // effective", ceres-solver issue 187). 0 turns it off; Plus still projects onto the
  // bounds. On the blob the costs of every iteration were the same and the surface the
  // same to the bit (docs/speed.md).
  options.max_num_line_search_step_size_iterations = 0;
  return options;
}

void StereoRefinementOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowError("stereo refinement options", field, expected);
  };
  require(coarsest_level >= 0, "coarsest_level", "must be ≥ 0");
  require(normal_only_from_level >= 0, "normal_only_from_level", "must be ≥ 0");
  require(window >= 1, "window", "must be ≥ 1");
  require(window_overlap >= 0, "window_overlap", "must be ≥ 0");
  require(rounds >= 1, "rounds", "must be ≥ 1");
  require(samples_per_pixel > 0, "samples_per_pixel", "must be > 0");
  require(min_density >= 1 && max_density >= min_density, "min_density/max_density",
          "must satisfy 1 ≤ min_density ≤ max_density");
  require(max_cameras >= 2, "max_cameras", "must be ≥ 2 (a stereo pair)");
  require(min_samples >= 3, "min_samples", "must be ≥ 3");
  require(image_sigma >= 0, "image_sigma", "must be ≥ 0");
  require(ncc_epsilon >= 0, "ncc_epsilon", "must be ≥ 0");
  require(ncc_loss_scale >= 0, "ncc_loss_scale", "must be ≥ 0");
  require(temporal_weight >= 0 && silhouette_weight >= 0 && membrane_weight >= 0 &&
              temporal_smoothness >= 0 && damping >= 0,
          "weights", "must be ≥ 0");
  require(slide_coherence >= 0, "slide_coherence", "must be ≥ 0 (0 = off)");
  require(silhouette_from_level >= 0, "silhouette_from_level", "must be ≥ 0");
  require(rim_band >= 0, "rim_band", "must be ≥ 0 (pixels; 0 = off)");
  require(min_patch_area > 0, "min_patch_area", "must be > 0 (pixels²)");
  require(detail_threshold >= 0, "detail_threshold", "must be ≥ 0 (edge lengths; 0 = off)");
  require(min_detail_patch_area > 0, "min_detail_patch_area", "must be > 0 (pixels²)");
  require(angle_weight_power >= 0, "angle_weight_power", "must be ≥ 0");
  require(outline_margin >= 0, "outline_margin", "must be ≥ 0 (pixels)");
  require(max_step > 0, "max_step", "must be > 0");
  require(adaptive_threshold >= 0, "adaptive_threshold", "must be ≥ 0");
  solver.Check();
  visibility.Check();
}

RefinementResult RefineStereo(const vision::ImageSequence& images, const LoopHierarchy& hierarchy,
                              const std::vector<Positions>& control, const vision::Bounds& bounds,
                              const StereoRefinementOptions& options, Progress* progress) {
  const Stopwatch start;
  options.Check();
  images.Check("stereo refinement");
  if (images.camera_count() < 2) ThrowError("stereo refinement", "cameras", "needs at least 2 cameras");
  if (control.empty()) ThrowError("stereo refinement", "control", "needs at least one frame");
  if (static_cast<int>(control.size()) != images.frame_count)
    ThrowError("stereo refinement", "control",
               std::to_string(control.size()) + " frames of control points for " +
                   std::to_string(images.frame_count) + " frames of images");
  for (std::size_t f = 0; f < control.size(); ++f)
    if (control[f].rows() != hierarchy.VertexCount(hierarchy.finest_level()) || !control[f].allFinite())
      ThrowError("stereo refinement", "control[" + std::to_string(f) + "]",
                 "must have #V(finest) = " + std::to_string(hierarchy.VertexCount(hierarchy.finest_level())) +
                     " finite rows");
  const PatchLevels patch_levels(hierarchy, control[control.size() / 2], images.cameras, options.min_patch_area,
                                 options.per_patch_levels && options.finest_level < 0,
                                 options.detail_threshold > 0.0 ? options.min_detail_patch_area : 0.0);
  const int finest_refined = options.finest_level >= 0 ? options.finest_level : patch_levels.finest_level();
  if (finest_refined > hierarchy.finest_level() || options.coarsest_level > finest_refined)
    ThrowError("stereo refinement options", "coarsest_level/finest_level",
               "must satisfy coarsest ≤ finest ≤ " + std::to_string(hierarchy.finest_level()));

  RefinementResult result;
  result.control = control;
  result.frames.resize(control.size());
  for (std::size_t f = 0; f < control.size(); ++f) result.frames[f].frame = static_cast<int>(f);
  SequenceState state{geometry::AnalyzeTrajectory(hierarchy, control), &result};
  FrameImageCache first_half(images, options.image_sigma), second_half(images, options.image_sigma);
  FrameImageCache* const caches[2] = {&first_half, &second_half};

  // Progress counts windows, per level the most either plan has (auto decides per level;
  // after each level the count moves on to the level's end).
  const int frames = static_cast<int>(control.size());
  const auto windows_of = [&](bool halves) { return PlanWindows(frames, options, halves).Count(); };
  const std::size_t windows = options.concurrent_halves == ConcurrentHalves::kAuto
                                  ? std::max(windows_of(false), windows_of(true))
                                  : windows_of(options.concurrent_halves == ConcurrentHalves::kOn);
  ProgressBegin(progress, "refinement",
                static_cast<std::size_t>(finest_refined - options.coarsest_level + 1) * options.rounds * windows);
  std::size_t done = 0;
  std::vector<char> active(hierarchy.FaceCount(options.coarsest_level), 1);
  for (int level = options.coarsest_level; level <= finest_refined; ++level) {
    const std::vector<char> moved = RefineLevel(images, hierarchy, bounds, options, level, active, caches, &state,
                                                progress, &done);
    done = static_cast<std::size_t>(level - options.coarsest_level + 1) * options.rounds * windows;
    ProgressUpdate(progress, done);
    if (level == finest_refined) break;
    // Adaptivity: a child face is refined when its parent was and one of the parent's
    // corners moved by more than the threshold at this level (details not small), and,
    // below the median level, when it still covers min_patch_area, or, where a corner moved
    // by more than detail_threshold, min_detail_patch_area (patch_levels.h).
    const geometry::Faces& F = hierarchy.LevelFaces(level);
    std::vector<char> next(hierarchy.FaceCount(level + 1), 0);
    for (int f = 0; f < hierarchy.FaceCount(level); ++f) {
      const int corner_moved = std::max({moved[F(f, 0)], moved[F(f, 1)], moved[F(f, 2)]});
      if (!active[f] || corner_moved == 0) continue;
      for (int k = 0; k < 4; ++k) {
        const int child = LoopHierarchy::ChildFace(f, k);
        next[child] = options.finest_level >= 0 || patch_levels.Resolved(level + 1, child) ||
                              (corner_moved == 2 && patch_levels.ResolvedForDetail(level + 1, child))
                          ? 1 : 0;
      }
    }
    active = std::move(next);
    if (std::find(active.begin(), active.end(), 1) == active.end()) break;  // nothing left to refine
  }
  ProgressEnd(progress);
  result.seconds = start.Seconds();
  return result;
}

}  // namespace subflow::solver
