// Shared fixture of the stereo refinement tests: the textured potato of motion_test_scene.h
// rendered (one static frame) from the limit surface of known control points into a dome
// of 8 cameras, so the true shape is representable, with its exact masks; a refinement
// window can be opened on it at any level.
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "geometry/closest_point.h"
#include "geometry/limit_evaluation.h"
#include "geometry/limit_tessellation.h"
#include "geometry/multires_shape.h"
#include "geometry/vertex_normals.h"
#include "solver/stereo/refinement_window.h"
#include "solver/stereo/stereo_refinement.h"
#include "tests/solver/motion_test_scene.h"
#include "vision/image_sequence.h"

namespace subflow::solver::testing {

struct RefinementScene {
  MotionTestScene scene = MakeMotionTestScene(2, 8);
  geometry::LimitTessellation tessellation;
  geometry::SparseMatrix limit;
  std::vector<cv::Mat> images;  // one per camera (a static scene: every frame the same)
  std::vector<cv::Mat> masks;
  vision::Bounds bounds{Eigen::Vector3d::Constant(-0.2), Eigen::Vector3d::Constant(0.2)};

  RefinementScene() {
    const int finest = scene.hierarchy.finest_level();
    tessellation = geometry::TessellateLimitSurface(scene.hierarchy.Topology(finest), 4);
    limit = geometry::LoopLimitEvaluator(scene.hierarchy.Topology(finest)).LimitMatrix(tessellation.samples);
    const Positions V = limit * scene.control;
    const vision::SyntheticRenderer renderer;
    const Positions normals = geometry::VertexNormals(V, tessellation.faces);
    for (const vision::Camera& camera : scene.cameras) {
      const vision::RenderedView view = renderer.Render(camera, V, tessellation.faces, normals, V, false);
      images.push_back(view.image);
      masks.push_back(view.mask);
    }
  }
  // The static sequence of `frames` frames, with the given masks (default: the exact ones).
  vision::ImageSequence Sequence(int frames, const std::vector<cv::Mat>* silhouettes = nullptr) const {
    const std::vector<cv::Mat>& chosen = silhouettes ? *silhouettes : masks;
    return {scene.cameras, 0, frames, [this](int camera, int) { return images[camera]; },
            [&chosen](int camera, int) { return chosen[camera]; }, {}};
  }
  // RMS distance of the limit surface of `control` to the true limit surface.
  double RmsDistanceToTruth(const Positions& control) const {
    const geometry::ClosestPointTree tree({limit * scene.control, tessellation.faces}, "truth");
    const Positions points = limit * control;
    double sum = 0.0;
    for (Eigen::Index i = 0; i < points.rows(); ++i)
      sum += (tree.Closest(points.row(i).transpose()).point - points.row(i).transpose()).squaredNorm();
    return std::sqrt(sum / static_cast<double>(points.rows()));
  }
  RefinementResult Refine(const Positions& control, int frames, StereoRefinementOptions options) const {
    options.solver.threads = 2;
    return RefineStereo(Sequence(frames), scene.hierarchy, std::vector<Positions>(frames, control), bounds, options);
  }
};

inline const RefinementScene& Scene() {
  static const RefinementScene scene;
  return scene;
}

// A window [first, last] of level `level` over `frames` static frames of `control`, every
// patch active; owns what the window points to.
struct OpenedWindow {
  StereoRefinementOptions options;
  vision::ImageSequence sequence;
  std::vector<Positions> control;
  geometry::Trajectory trajectory;
  std::unique_ptr<FrameImageCache> cache;
  RefinementLevel level;
  RefinementWindow window;

  OpenedWindow(const RefinementScene& scene, const Positions& shape, int frames, int level_index, int first,
               int last, StereoRefinementOptions refinement = {},
               const std::vector<cv::Mat>* silhouettes = nullptr)
      : OpenedWindow(scene, std::vector<Positions>(frames, shape), level_index, first, last, refinement,
                     silhouettes) {}
  // The same with one shape per frame (the images stay the static scene's).
  OpenedWindow(const RefinementScene& scene, std::vector<Positions> shapes, int level_index, int first, int last,
               StereoRefinementOptions refinement = {}, const std::vector<cv::Mat>* silhouettes = nullptr)
      : options(refinement),
        sequence(scene.Sequence(static_cast<int>(shapes.size()), silhouettes)),
        control(std::move(shapes)),
        trajectory(geometry::AnalyzeTrajectory(scene.scene.hierarchy, control)),
        cache(std::make_unique<FrameImageCache>(sequence, options.image_sigma)) {
    const geometry::LoopHierarchy& hierarchy = scene.scene.hierarchy;
    level = PrepareLevel(hierarchy, sequence.cameras, options, trajectory, level_index,
                         std::vector<char>(hierarchy.FaceCount(level_index), 1));
    window = OpenWindow(level, hierarchy, sequence.cameras, options, trajectory, control, cache.get(), first, last);
  }
  OpenedWindow(const OpenedWindow&) = delete;
};

// The scene's control points scaled about their centroid so that the surface moves
// inwards by about `pixels` pixels at 0.6 m (where the cameras are).
inline Positions Shrunk(const RefinementScene& refinement, double pixels) {
  const Positions& truth = refinement.scene.control;
  const Eigen::RowVector3d centre = truth.colwise().mean();
  const double radius = (truth.rowwise() - centre).rowwise().norm().mean();
  const double shrink = pixels * 0.6 / refinement.scene.cameras[0].K()(0, 0);
  Positions shrunk = truth;
  for (Eigen::Index v = 0; v < shrunk.rows(); ++v)
    shrunk.row(v) = centre + (truth.row(v) - centre) * (1.0 - shrink / radius);
  return shrunk;
}

// Smooth normal bumps on the level-1 details (about one pixel: 1.4 mm at 0.6 m).
inline Positions Perturbed(const geometry::LoopHierarchy& hierarchy, const Positions& control, double amplitude) {
  geometry::MultiresShape shape = geometry::MultiresShape::Analyze(hierarchy, control);
  Positions& d1 = shape.Detail(1);
  const Positions c1 = shape.Synthesize(hierarchy, 1);
  for (Eigen::Index v = 0; v < d1.rows(); ++v) {
    const Eigen::Vector3d p = c1.row(v).transpose().normalized();
    d1(v, 0) += amplitude * std::sin(3.0 * p.x() + 1.0) * std::cos(2.0 * p.y() - 0.5);
  }
  return shape.Synthesize(hierarchy, hierarchy.finest_level());
}

}  // namespace subflow::solver::testing
