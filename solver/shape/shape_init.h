// Shape initialization (method §4.1): from multi-view video to a time-varying shape on
// ONE subdivision connectivity.
//
//   per frame f:  silhouettes (mask | background difference | motion evidence, eq. 23)
//                 → evidence voxels → 3D morphology → occupancy        (vision/voxel_carving.h)
//                 → iso-surface: the visual hull H_f                     (geometry/isosurface.h)
//   reference frame r:  T0 = simplification of H_r to a distance bound, and the number of
//                 levels, from the subject's detail and the images' resolution
//                 (solver/shape/base_resolution.h, geometry/simplify.h)
//                 → LoopHierarchy of T0 with that many levels
//   every frame:  control points of levels 0..n fitted to H_f along limit normals
//                 (solver/shape/hierarchy_fit.h), frames visited outwards from r so that each
//                 starts from its neighbour's fitted base (the multires analysis of a frame, when
//                 needed, is geometry::MultiresShape::Analyze of its finest control points).
//
// Snapping along normals only moves points across the surface: vertices of different
// frames correspond only approximately (tangential drift). Motion initialization
// (normal flow) is what makes them trajectories.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "geometry/isosurface.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"
#include "core/progress.h"
#include "geometry/simplify.h"
#include "solver/shape/base_resolution.h"
#include "solver/shape/hierarchy_fit.h"
#include "solver/shape/surface_registration.h"
#include "vision/concavity_carving.h"
#include "vision/dataset.h"
#include "vision/silhouettes.h"
#include "vision/standing_evidence.h"
#include "vision/still_evidence.h"
#include "vision/voxel_carving.h"

namespace subflow::solver {

struct ShapeInitOptions {
  vision::SilhouetteOptions silhouettes;
  // Cameras whose silhouettes come from a background estimated from the video: what
  // stands (almost) still in the take is added to them (vision/standing_evidence.h).
  vision::StandingEvidenceOptions standing;
  // When no frame has any evidence (no masks, no background images, nothing moves: a
  // still set of one frame, or a take in which nobody moves), or with silhouettes.source
  // kStill: the still set formed by the reference frame of every camera is every frame's
  // evidence: its differences to a plain backdrop when every camera has one
  // (vision/plain_backdrop.h, still.backdrop), else its photo-consistency
  // (vision/still_evidence.h).
  vision::StillEvidenceOptions still;
  vision::VoxelCarvingOptions carving;
  // Every frame's hull is carved where the cameras see through it (concavities the
  // silhouettes cannot reach: vision/concavity_carving.h).
  vision::ConcavityCarvingOptions concavities;
  geometry::IsosurfaceOptions isosurface;
  // T0's simplification: its filters, the face count when base_distance_voxels = 0, the
  // face floor and cap of the distance bound (min_face_count, max_face_count) otherwise.
  geometry::SimplifyOptions simplify;
  // Every frame's fit starts from its neighbour's fitted base registered to the frame's
  // hull (non-rigid ICP, solver/shape/surface_registration.h), so that the surface
  // follows parts that moved by more than a snap along the normals reaches.
  SurfaceRegistrationOptions registration;
  HierarchyFitOptions fit;
  // T0 = the reference hull simplified until it would leave this many voxels (of the
  // carving grid) of the hull, both ways (solver/shape/base_resolution.h); 0 = by count
  // (simplify.target_face_count faces).
  double base_distance_voxels = 1.0;
  // Subdivision levels above the base mesh (the hierarchy has levels 0..levels); −1 =
  // automatic: the fewest whose finest edges project to about finest_edge_pixels where
  // the subject is smooth (T0's faces raised to match; base_resolution.h), within
  // max_finest_faces faces at the finest level.
  int levels = -1;
  double finest_edge_pixels = 2.0;
  // The cost bound of the automatic levels: motion initialization works on every finest
  // vertex and refinement on every finest patch, so their time and memory grow with the
  // finest level's faces. 65,536 is 2.6× the shared blob's 25,216 at 2 px; a 1088×1920
  // take at 2 px wanted 600,064 (pose2sim_multiperson: 3.5 s a frame to fit, 11 GB and
  // minutes per motion step), and now gets its finest edges at about 6 px instead.
  int max_finest_faces = 65536;
  // Frame whose visual hull gives the base connectivity; −1 = the middle frame.
  int reference_frame = -1;
  // Frames [first_frame, first_frame + frame_count); frame_count −1 = to the end.
  int first_frame = 0;
  int frame_count = -1;
  // Motion initialization and stereo refinement see every camera's images reduced so
  // that the finest level's edges of the reference frame's fitted surface project to
  // about this many pixels (vision/working_scale.h: SurfaceScale; never enlarged): finer
  // images hold detail the surface cannot represent and cost time in proportion to
  // their pixels. The scenes the accuracy floors were measured on have median finest
  // edges of 1.0–2.0 px (../shared/data/blob 2.0, bust_front 1.7–2.0, take_small 1.4–1.5)
  // and are left at their size; the 1088×1920 pose2sim take (8–11 px) is reduced to
  // about a third. 0 = the stored size. The shape stage chooses the scales
  // (StageState::image_scales), the later stages read them.
  double image_edge_pixels = 3.0;

  void Check() const;  // throws subflow::Error naming the field
};

struct FrameShapeInit {
  int frame = 0;
  // The frame whose evidence gave the hull: `frame` itself, or for a frame without any
  // evidence (vision::LacksEvidence: no masks, no background, nothing moves) the nearest
  // frame with evidence (the earlier one on a tie), whose hull and carving figures are
  // taken, with a warning in carving.warnings.
  int hull_from_frame = 0;
  vision::CarvingResult carving;             // figures; its occupancy volume is released
  vision::ConcavityCarvingReport concavities;  // the hull's carving by free space
  geometry::IsosurfaceSummary isosurface;
  geometry::TriangleMesh hull;               // the visual-hull iso-surface H_f (empty with a ShapeFrameStore)
  int hull_vertices = 0, hull_faces = 0;     // the hull's size (with or without a store)
  std::vector<geometry::Positions> control;  // fitted control points, levels 0..n (empty with a store)
  SurfaceRegistrationReport registration;    // the starting base registered to the hull
  std::vector<LevelFitSummary> fit;          // per level
  double carve_seconds = 0, isosurface_seconds = 0, fit_seconds = 0;  // carve: with the concavities
};

// Where InitializeShape keeps each frame's visual hull and fitted control points. Without
// one (nullptr) they stay in FrameShapeInit::hull and ::control. The `shape` command gives
// one that writes them into its stage folder as they are made and reads a hull back when
// it is needed again (the reference frame's for the base mesh, each frame's for its fit),
// so that the stage's memory does not grow with the take's length (docs/cluster.md).
// LoadHull must return exactly what StoreHull was given.
class ShapeFrameStore {
 public:
  virtual ~ShapeFrameStore() = default;
  virtual void StoreHull(int frame, const geometry::TriangleMesh& hull) = 0;
  virtual geometry::TriangleMesh LoadHull(int frame) const = 0;
  // `levels`: the frame's control points of levels 0..n of `hierarchy`.
  virtual void StoreControl(int frame, const geometry::LoopHierarchy& hierarchy,
                            const std::vector<geometry::Positions>& levels) = 0;
};

struct ShapeInitResult {
  int reference_frame = 0;
  geometry::Positions reference_control;  // the reference frame's finest fitted control points
  geometry::TriangleMesh base_mesh;  // T0 (level 0 at the reference frame, before fitting)
  geometry::SimplifySummary simplify;
  // How T0 and the levels were chosen (base_resolution.h; its `base` is moved to base_mesh).
  BaseResolution resolution;
  std::shared_ptr<const geometry::LoopHierarchy> hierarchy;
  std::vector<FrameShapeInit> frames;  // in frame order
  // Per camera, the background estimated from the video (vision::EstimateBackgrounds;
  // the figures only, images released) for cameras without masks and background image;
  // empty when none was estimated.
  std::vector<vision::EstimatedBackground> estimated_backgrounds;
  double estimate_background_seconds = 0;
  // Per camera, the standing silhouette added to every frame's (vision/standing_evidence.h;
  // masks released, figures kept); empty when none was computed.
  std::vector<vision::Silhouette> standing;
  // The still set's evidence, when it was used (used_still): against a plain backdrop
  // (used_backdrop; `backdrops`: every camera's figures, also when some were not plain),
  // else the photo-consistency (`still`, silhouettes released).
  bool used_still = false;
  bool used_backdrop = false;
  std::vector<vision::PlainBackdrop> backdrops;
  // With used_backdrop, per camera: the backdrop silhouette (CV_8UC1, 0 / 255, at the
  // evidence's scale, raw image coordinates): the object's outline in every frame, which
  // the refinement takes as a mask (StageState::outlines).
  std::vector<cv::Mat> outlines;
  double backdrop_seconds = 0;  // measuring the backdrops and their silhouettes
  vision::StillEvidence still;
  // Per camera, the scale of the images the evidence was computed on (1 = stored size;
  // VoxelCarvingOptions::max_pixels_per_voxel).
  std::vector<double> evidence_scales;
  double simplify_seconds = 0;
  // The whole stage, wall time (frames are carved, meshed and fitted side by side: the
  // frames' carve / isosurface / fit seconds add up to more).
  double seconds = 0;

  // One line: frames, base mesh, levels, mean silhouette IoU, seconds.
  std::string BriefReport() const;
};

// Runs the whole stage on `dataset`. Throws subflow::Error on bad input (see the
// vision/geometry stages), and when no frame has any evidence of the object; warnings
// (cameras excluded, object touching the bounds, a frame without evidence) are logged
// and kept in each frame's carving result.
// With `store`, the hulls and control points go there (see ShapeFrameStore), not into
// the frames of the result; the results are the same.
ShapeInitResult InitializeShape(const vision::Dataset& dataset, const ShapeInitOptions& options,
                                Progress* progress = nullptr, ShapeFrameStore* store = nullptr);

}  // namespace subflow::solver
