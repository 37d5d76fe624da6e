// Where a synthetic camera's image samples land on the surface, with or without lens
// distortion (for vision/synthetic_render.h).
//
// A sample at raw (distorted) image point p sees along the ray of p: direction
// camera.BackProject(p) from the camera centre. The canvas is a pinhole z-buffer camera
// `factor` times denser than the undistorted image, shifted and grown to cover the
// undistorted positions of the whole raw image:
//   canvas pixel (i, j) samples the undistorted image point u = u0 + (i, j) / factor.
// Without distortion the canvas is SupersampledCamera(camera, factor) and the raw sample
// (s·x + i + ½)/s − ½ falls exactly on canvas pixel (s·x + i): face and barycentrics are
// the z-buffer's. With distortion, a raw point's undistorted position is interpolated
// bilinearly from the exact undistortion of the raw pixel-corner grid (error ≪ 0.01 px for
// smooth distortion), the nearest canvas pixel gives the face, and the barycentrics are
// the exact intersection of the ray with that face's plane (so the surface point is on
// the ray; only the face choice is nearest-sample).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/zbuffer.h"

namespace subflow::vision {

struct CanvasHit {
  int face = -1;                       // −1: the ray meets nothing
  double w1 = 0.0, w2 = 0.0;           // X = (1 − w1 − w2) a + w1 b + w2 c
};

class SampleCanvas {
 public:
  SampleCanvas(const Camera& camera, int factor);
  // Renders (V, F) into the canvas.
  void Render(const geometry::Positions& V, const geometry::Faces& F, const ZBufferOptions& options);
  // The hit of the sample (i, j) of raw pixel (x, y): raw point ((s x + i + ½)/s − ½, …).
  CanvasHit Hit(int x, int y, int i, int j, const geometry::Positions& V, const geometry::Faces& F) const;

 private:
  Eigen::Vector2d Undistorted(double px, double py) const;

  Camera camera_, canvas_;
  int factor_ = 1;
  bool distorted_ = false;
  Eigen::Vector2d u0_ = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector2d> corners_;  // (W + 1) × (H + 1) undistorted raw pixel corners
  ZBuffer zbuffer_;
};

}  // namespace subflow::vision
