// What surrounds a synthetic subject: a textured floor or room, moving distractors, and
// soft shadows of the subject from the key light (for `subflow synth`).
//
// Geometry (world metres, +z up; `centre` = the subject's box centre over all frames,
// `floor_z` = its lowest point over all frames − 2 mm, `reach` = the rig's camera
// distance + 0.3 m, so walls stand behind every camera of a ring):
//   floor  the square |x − cx|, |y − cy| ≤ reach at z = floor_z, facing +z;
//   room   the floor and four walls at x, y = c ± reach, from floor_z to floor_z + 1.5 m,
//          facing the centre (no ceiling): every camera sees a textured backdrop;
//   walker a vertical capsule-like prism (radius 5 cm, 45 cm high) standing on the floor,
//          pacing along x at y = cy + 0.42 m (outside the working volume), x = cx +
//          0.45 sin(2π f / 150) at frame f;
//   crosser a ball (radius 4 cm) 0.2 m in front of camera 0, moving across its view along
//          its image x axis: offset 0.25 sin(2π f / 60 + 1) m; it hides part of the subject
//          in camera 0 for some frames (the masks then show only what is visible).
// Faces are counter-clockwise seen from where they are meant to be seen (inside the room,
// above the floor, outside the movers), so back-face culling stays valid.
//
// Soft shadows: the key light (a direction L, vision/synthetic_render.h) is an area light
// of angular radius `shadow_cone_degrees`, sampled by `shadow_samples` directions (a Vogel
// spiral in the cone). For each direction, a shadow map = a z-buffer of the subject from a
// camera 20 m away along the direction (1024² px, framing the subject's bounding sphere);
// the light fraction at a point X is the mean over the directions of [X is not behind the
// subject in that map by more than `shadow_bias`] (points outside a map are lit).
// The background images (background/<cam>.png) show the static environment only: no
// subject, no movers, no shadows — a clean plate taken before the capture.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/zbuffer.h"

namespace subflow::vision {

struct EnvironmentOptions {
  std::string kind = "none";        // "none", "floor" or "room"
  std::string distractors = "none";  // "none", "walker", "crosser" or "both"
  bool shadows = false;             // soft shadows of the subject from the key light
  int shadow_samples = 8;           // directions sampling the area light
  double shadow_cone_degrees = 3.0;  // angular radius of the key light
  double shadow_bias = 0.002;       // metres along the light's depth

  void Check() const;  // throws subflow::Error naming the option
};

// A mesh with rest (texture) coordinates.
struct TexturedMesh {
  geometry::Positions V, rest;
  geometry::Faces F;
};

// Appends `part` to `mesh` (faces re-indexed).
void AppendMesh(TexturedMesh* mesh, const TexturedMesh& part);

class SyntheticEnvironment {
 public:
  SyntheticEnvironment() = default;
  // `subject_low`, `subject_high`: the subject's box over all frames; `cameras`: the rig;
  // `camera_distance`: the rig's distance from its target.
  SyntheticEnvironment(const EnvironmentOptions& options, const Eigen::Vector3d& subject_low,
                       const Eigen::Vector3d& subject_high, const std::vector<Camera>& cameras,
                       double camera_distance);

  const EnvironmentOptions& options() const { return options_; }
  // Floor and walls (empty when kind = none).
  const TexturedMesh& static_geometry() const { return static_; }
  // Static geometry and the movers at `frame`.
  TexturedMesh AtFrame(int frame) const;

 private:
  EnvironmentOptions options_;
  TexturedMesh static_;
  TexturedMesh walker_, crosser_;  // at rest, centred on the origin
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  double floor_z_ = 0.0;
  Eigen::Vector3d crosser_base_ = Eigen::Vector3d::Zero(), crosser_direction_ = Eigen::Vector3d::UnitX();
};

// Shadow maps of one frame's subject (see the file comment).
class SoftShadows {
 public:
  SoftShadows() = default;
  SoftShadows(const EnvironmentOptions& options, const Eigen::Vector3d& light_direction,
              const geometry::Positions& subject_V, const geometry::Faces& subject_F);
  bool enabled() const { return !maps_.empty(); }
  // Fraction of the light reaching X, in [0, 1] (1 when disabled).
  double LightFraction(const Eigen::Vector3d& X) const;

 private:
  std::vector<ZBuffer> maps_;
  double bias_ = 0.002;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero(), light_ = Eigen::Vector3d::UnitZ();
  double radius_ = 0.0, cone_tangent_ = 0.0;  // the subject's bounding sphere, the light's cone
};

}  // namespace subflow::vision
