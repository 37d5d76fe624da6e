// Shared fixtures of the motion tests: a textured "potato" (vision's rigid synthetic scene)
// rendered by vision's synthetic renderer into a dome of cameras, a Loop hierarchy whose
// finest control points are fitted to it, and known rigid motions applied to both.
#pragma once

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <tbb/parallel_for.h>

#include "geometry/closest_point.h"
#include "geometry/icosphere.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"
#include "geometry/vertex_normals.h"
#include "solver/shape/surface_snapping.h"
#include "vision/camera.h"
#include "vision/camera_rig.h"
#include "vision/synthetic_render.h"
#include "vision/synthetic_scene.h"

namespace subflow::solver::testing {

using geometry::Positions;

// A rigid transform x ↦ R (x − centre) + centre + t.
struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();

  Positions Apply(const Positions& x) const {
    Positions y(x.rows(), 3);
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      y.row(i) = (R * (x.row(i).transpose() - centre) + centre + t).transpose();
    return y;
  }
};

struct MotionTestScene {
  geometry::TriangleMesh mesh;  // the object at frame 0
  Positions rest;               // texture coordinates
  std::vector<vision::Camera> cameras;
  geometry::LoopHierarchy hierarchy;
  Positions control;            // finest control points fitted to `mesh`
};

// Base: icosphere(1) (42 vertices); `levels` Loop levels (2 → 642 finest control points).
inline MotionTestScene MakeMotionTestScene(int levels = 2, int camera_count = 8) {
  vision::SyntheticSceneOptions scene_options;
  scene_options.scene = "rigid";
  scene_options.frame_count = 1;
  scene_options.subdivisions = 4;
  const vision::SyntheticScene scene = vision::MakeSyntheticScene(scene_options);
  vision::CameraRigOptions rig;
  rig.rig = "dome";
  rig.camera_count = camera_count;
  const geometry::TriangleMesh base = geometry::MakeIcosphere(1, 0.08);
  MotionTestScene result{scene.Mesh(0), scene.rest, vision::MakeCameraRig(rig),
                         geometry::LoopHierarchy(base.F, base.vertex_count(), levels), Positions()};
  Positions control = result.hierarchy.Refine(base.V, 0, levels);
  for (Eigen::Index i = 0; i < control.rows(); ++i) control.row(i) *= 0.08 / control.row(i).norm();
  const geometry::ClosestPointTree tree(result.mesh, "potato");
  SurfaceSnapOptions snap;
  snap.iterations = 12;
  result.control = SnapToSurface(result.hierarchy, levels, control, tree, snap);
  return result;
}

// Gray images (CV_8UC1) of the mesh V (faces and texture of the scene) in every camera.
inline std::vector<cv::Mat> RenderGray(const MotionTestScene& scene, const Positions& V) {
  const vision::SyntheticRenderer renderer;
  const Positions normals = geometry::VertexNormals(V, scene.mesh.F);
  std::vector<cv::Mat> images(scene.cameras.size());
  tbb::parallel_for(std::size_t{0}, scene.cameras.size(), [&](std::size_t k) {
    images[k] = renderer.Render(scene.cameras[k], V, scene.mesh.F, normals, scene.rest, false).image;
  });
  return images;
}

inline Eigen::Vector3d Centroid(const Positions& x) { return x.colwise().mean().transpose(); }

}  // namespace subflow::solver::testing
