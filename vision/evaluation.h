// Scoring a reconstruction against ground truth (`subflow eval DATASET RESULT`).
//
// Inputs: the true meshes (DATASET/groundtruth/mesh/<frame>.ply, ../shared/DATASET.md)
// and the result's meshes (RESULT/meshes/<frame>.ply, ../shared/OUTPUT.md), both with
// the same vertex count, order and faces at every frame. Distances are in world units.
//
// Surface figures per frame (R = result surface, T = true surface, d(x, S) = distance
// from x to the nearest point of S, samples = SampleSurface, area-weighted):
//   accuracy      the `accuracy_percentile` (90) percentile of d(r, T) over samples r of R
//   completeness  fraction of samples t of T with d(t, R) ≤ threshold
//                 (default threshold: 1 % of the diagonal of T's bounding box at frame 0)
//   chamfer       (mean_r d(r, T) + mean_t d(t, R)) / 2
//   hausdorff     max(max_r d(r, T), max_t d(t, R))   (over the samples)
// Scene flow per frame f < last (for each result vertex x_i at f):
//   (face, u, v) = the closest point c_i of T_f to x_i; the true position of that
//   material point at f + 1 is c'_i = the same (face, u, v) on T_{f+1};
//   true motion m_i = c'_i − c_i; recovered motion r_i = (vx, vy, vz) of vertex i when
//   the result PLY has them, else x_i(f + 1) − x_i(f);
//   EPE_i = |r_i − m_i|; reported: mean, median, mean |m_i|, relative = mean EPE / mean |m_i|.
// Overall: accuracy = percentile of the pooled samples of all frames; completeness,
// chamfer = mean over frames; hausdorff = max; EPE mean / median / relative pooled over
// all vertices of all frames.
//
// Observed surface (when the dataset's cameras are given): the part of T that at least
// `min_views` cameras see (vision/evaluation_visibility.h, tolerance `visibility_tolerance`),
// since nothing can be known about the rest. The same figures restricted to it:
//   completeness, mean_truth_to_result   over the true samples t that are observed;
//   accuracy, mean_result_to_truth       over the result samples r whose closest true
//                                        point is observed (a bulge into a hollow counts);
//   flow                                 over the result vertices whose closest true point
//                                        is observed;
//   observed_fraction                    of the true samples, observed;
//   pixel_footprint                      mean over the observed true samples of their pixel
//                                        footprint (world units per pixel), so that
//   accuracy_px = accuracy / pixel_footprint.
// Surfaces only (score_flow = false, e.g. visual hulls): result frames may change their
// vertex count and faces; no flow is computed.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/closest_point.h"
#include "core/progress.h"
#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::vision {

struct EvaluationOptions {
  double threshold = 0.0;              // completeness distance; 0 = 1 % of the true bbox diagonal
  int samples = 50000;                 // area-weighted samples per surface and frame
  double accuracy_percentile = 90.0;   // in (0, 100]
  int min_views = 2;                   // observed surface: seen by at least this many cameras
  double visibility_tolerance = 0.0;   // depth tolerance of visibility; 0 = 0.25 % of the true bbox diagonal
  bool score_flow = true;              // false: surfaces only, topology may change per frame

  void Check() const;  // throws subflow::Error naming the field
};

struct SurfaceScores {
  double accuracy = 0.0, completeness = 0.0, chamfer = 0.0, hausdorff = 0.0;
  double mean_result_to_truth = 0.0, mean_truth_to_result = 0.0;
};

struct FlowScores {
  bool evaluated = false;  // false at the last frame
  double epe_mean = 0.0, epe_median = 0.0, true_motion_mean = 0.0, epe_relative = 0.0;
  // Mean magnitude of the error's component along the true surface normal (the part a
  // shape error makes) and of its component in the tangent plane (sliding along the surface).
  double epe_normal_mean = 0.0, epe_tangential_mean = 0.0;
};

// The figures on the observed surface (see the file comment).
struct ObservedScores {
  bool evaluated = false;  // false without cameras
  SurfaceScores surface;
  FlowScores flow;
  double observed_fraction = 0.0, pixel_footprint = 0.0, accuracy_px = 0.0;
};

struct FrameScores {
  int frame = -1;  // −1 for the overall figures
  SurfaceScores surface;
  FlowScores flow;
  ObservedScores observed;
};

struct EvaluationReport {
  std::vector<FrameScores> frames;
  FrameScores overall;
  double threshold = 0.0;
  int samples = 0;
  double accuracy_percentile = 90.0;
  std::string flow_source;  // "vx vy vz", "vertex differences" or "none"
  std::string surfaces = "meshes";  // what was scored: the result's meshes/ or hull/
  int camera_count = 0;     // cameras of the observed-surface figures (0 = not computed)
  int min_views = 2;
  double visibility_tolerance = 0.0;

  std::string Table() const;  // one line per frame + overall, fixed-width columns
  std::string Json() const;   // the same figures as a JSON document
};

// `count` points on the surface, area-weighted and deterministic: triangle i gets
// floor(C_i) − floor(C_{i−1}) points (C = cumulative area · count / total area), placed
// by an R2 low-discrepancy sequence folded into the triangle. #count×3.
geometry::Positions SampleSurface(const geometry::TriangleMesh& mesh, int count);

// A frame of a sequence: the mesh and, when present, the recovered motion (#V×3).
struct EvaluationFrame {
  geometry::TriangleMesh mesh;
  std::optional<geometry::Positions> motion;
};

// Core: evaluates `frame_count` frames given loaders of the true mesh and the result at
// a frame (each called about once per frame, a window of two frames is kept). Checks
// that vertex counts and faces do not change between frames (throws subflow::Error
// naming `result_source` / `truth_source` and the frame).
EvaluationReport EvaluateSequence(int frame_count,
                                  const std::function<geometry::TriangleMesh(int)>& load_truth,
                                  const std::function<EvaluationFrame(int)>& load_result,
                                  const EvaluationOptions& options, Progress* progress = nullptr,
                                  const std::string& truth_source = "ground truth",
                                  const std::string& result_source = "result",
                                  const std::vector<Camera>& cameras = {});

// Reads DATASET/groundtruth/mesh/*.ply and RESULT/<surfaces>/*.ply and evaluates them,
// with DATASET/cameras.json's cameras for the observed surface (not scored when the
// dataset has no cameras.json). surfaces = "meshes" (a
// reconstruction, ../shared/OUTPUT.md) or "hull" (`subflow hull`'s visual hulls: surfaces
// only, options.score_flow is set false). Throws subflow::Error for a missing directory, a
// gap in the frame numbers, different frame counts, or (when scoring flow) meshes whose
// vertex count / faces change between frames.
EvaluationReport EvaluateReconstruction(const std::string& dataset_directory,
                                        const std::string& result_directory,
                                        const EvaluationOptions& options,
                                        Progress* progress = nullptr,
                                        const std::string& surfaces = "meshes");

// Frame files "<dir>/000000.ply" … of a directory, checked to be contiguous from 0, or,
// when `first_frame` is given, from the first frame present (returned there). Throws
// naming the directory when it is missing or empty, and the first missing frame.
std::vector<std::string> ListFrameMeshes(const std::string& directory, int* first_frame = nullptr);

}  // namespace subflow::vision
