// New views of a result: cameras that look at the object from around it.
//   LookAtCamera  centre `eye`, optical axis towards `target`, image up along `up`
//                 (R's rows: x = right = forward × up, y = down = forward × right,
//                 z = forward; the DATASET.md convention).
//   Turntable     `count` cameras on a circle around the axis `up` through the bounding
//                 sphere's centre, at `elevation_degrees` above its equator, at the
//                 distance where the sphere fills `fill` of the smaller image side.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"

namespace subflow::output {

vision::Camera LookAtCamera(const std::string& name, int width, int height, double focal,
                            const Eigen::Vector3d& eye, const Eigen::Vector3d& target, const Eigen::Vector3d& up);

struct TurntableOptions {
  int count = 8;                  // views around the object
  int width = 640, height = 480;  // pixels
  double elevation_degrees = 20;  // above the plane through the centre normal to `up`
  double fill = 0.8;              // share of the smaller image side the bounding sphere covers
  double focal = 800;             // pixels
};

std::vector<vision::Camera> TurntableCameras(const geometry::Positions& V, const Eigen::Vector3d& up,
                                             const TurntableOptions& options);

// The world's up direction as a set of cameras see it: the mean of their image-up axes
// (−y of each camera, in world coordinates), normalized; +Z when there is no camera or
// the mean vanishes.
Eigen::Vector3d CamerasUp(const std::vector<vision::Camera>& cameras);

}  // namespace subflow::output
