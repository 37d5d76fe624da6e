// Synthetic camera rigs looking at a target point, in the convention of vision/camera.h
// (+z forward, +x right, +y down; world +z up). Camera k is named "cam%02d".
//
//   ring          all cameras on one circle of radius `distance` around `target`, at
//                 elevation `elevation_deg`, azimuths 360°/N apart starting at −90°
//                 (camera 0 on the −y side, like ../shared/data/blob).
//   dome          one camera straight above, the others split between a low ring
//                 (elevation_deg, ~60 %) and a high ring (50°, azimuths offset by half
//                 a step).
//   partial-dome  like dome without the top camera, but azimuths span only the front
//                 half (−180°..0°, centred on −90°), and every third camera has a
//                 narrower field of view (focal × narrow_focal_factor): it sees only part
//                 of the working volume.
//   front         every camera in front of the subject (the −y side): azimuths evenly
//                 from −165° to −15°, elevations alternating elevation_deg and
//                 elevation_deg + 25°, one focal length: nothing sees the back half.
// The look-at frame: z = (target − C)/|·|, x = z × up / |·| (up = +z, or +y when looking
// straight down), y = z × x; R has rows x, y, z and t = −R C. Principal point at the
// image centre ((W − 1)/2, (H − 1)/2), square pixels.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "vision/camera.h"

namespace subflow::vision {

struct CameraRigOptions {
  std::string rig = "ring";      // "ring", "dome", "partial-dome" or "front"
  int camera_count = 10;
  int width = 320, height = 240;
  double focal = 0.0;            // px; 0 = 420 × width / 320 (the blob dataset's field of view)
  double distance = 0.6;         // metres from target to each camera centre
  double elevation_deg = 10.0;   // elevation of the (low) ring
  double narrow_focal_factor = 1.8;  // partial-dome: focal multiplier of the narrow cameras

  void Check() const;  // throws subflow::Error naming the field
};

std::vector<Camera> MakeCameraRig(const CameraRigOptions& options,
                                  const Eigen::Vector3d& target = Eigen::Vector3d::Zero());

// A camera at `centre` looking at `target` (see the look-at frame above).
Camera LookAtCamera(const std::string& name, int width, int height, double focal,
                    const Eigen::Vector3d& centre, const Eigen::Vector3d& target);

// The same camera sampling the image `factor` times more densely in x and y: pixel
// (i, j) of the result samples the image point ((i + 0.5)/factor − 0.5, (j + 0.5)/factor
// − 0.5) of `camera`, so box-filtering factor × factor blocks gives back `camera`'s pixels.
Camera SupersampledCamera(const Camera& camera, int factor);

}  // namespace subflow::vision
