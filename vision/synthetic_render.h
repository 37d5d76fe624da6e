// The synthetic renderer behind `subflow synth`: renders a SyntheticScene into a camera
// rig and writes a dataset in the layout of ../shared/DATASET.md with ground truth.
//
// Image formation (linear radiance, then sRGB-encoded 8-bit PNG):
//   L = albedo(rest(X)) · (ambient + Σ_lights strength · max(0, n(X) · l))
//   X      the surface point seen at a sample: ZBuffer face + barycentrics;
//   rest   the same barycentric combination of the rest positions (texture moves with
//          the surface, vision/procedural_texture.h);
//   n      the normalized barycentric combination of the frame's vertex normals;
//   lights directional, fixed in world: key (azimuth −35°, elevation 50°, 0.75), fill
//          (140°, 30°, 0.25), ambient 0.12; the key light's term is multiplied by the
//          soft-shadow light fraction when shadows are on (vision/synthetic_environment.h).
// Scene = the subject's faces first (their albedo, their pixels make the mask), then the
// environment's (floor, walls, distractors: a coarser albedo, never in the mask).
// Lens distortion (SynthOptions::distortion): every sample is traced along the ray of its
// raw (distorted) image point (vision/synthetic_canvas.h), so images and masks are what a
// distorting lens records.
// Anti-aliasing: every pixel is the box-filtered mean of supersample × supersample
// samples (SupersampledCamera), the mask is "more than half of the samples cover the
// object" (as the blob dataset's Cryptomatte coverage > 0.5). Background: a constant
// dark radiance 0.03 ("dark") or a low-contrast value-noise texture fixed in the image
// ("texture"); background/<cam>.png is the same camera without the object. Gray cameras
// record the luminance 0.2126 R + 0.7152 G + 0.0722 B. Optional Gaussian sensor noise
// of σ grey levels (of 255) is added before quantization, seeded per camera and frame.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/progress.h"
#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/camera_rig.h"
#include "vision/procedural_texture.h"
#include "vision/synthetic_environment.h"
#include "vision/synthetic_scene.h"
#include "vision/working_volume.h"

namespace subflow::vision {

struct CanvasHit;  // vision/synthetic_canvas.h

struct SyntheticRenderOptions {
  int supersample = 3;             // samples per pixel along x and y (1 = none)
  std::string background = "dark";  // "dark" or "texture"
  double noise_sigma = 0.0;        // Gaussian sensor noise, grey levels of 255
  ProceduralAlbedoOptions albedo;  // the surface texture
  ProceduralAlbedoOptions environment_albedo = EnvironmentAlbedo();  // floor, walls, distractors

  void Check() const;
  static ProceduralAlbedoOptions EnvironmentAlbedo();  // 3 cm cells, strong contrast, seed 7
};

// What one image shows: the subject's faces are F's first `subject_face_count` rows.
struct SceneView {
  const geometry::Positions& V;        // #V×3
  const geometry::Faces& F;            // #F×3
  const geometry::Positions& normals;  // #V×3 unit vertex normals
  const geometry::Positions& rest;     // #V×3 texture coordinates
  int subject_face_count;
  const SoftShadows* shadows = nullptr;  // null: no shadows
};

struct RenderedView {
  cv::Mat image;  // CV_8UC1 (gray camera) or CV_8UC3 (BGR, colour camera)
  cv::Mat mask;   // CV_8UC1, 255 where more than half of the samples see the object
};

class SyntheticRenderer {
 public:
  explicit SyntheticRenderer(const SyntheticRenderOptions& options = {});

  // Renders the mesh (V, F) with per-vertex normals (#V×3) and rest positions (#V×3).
  // `noise_seed` seeds the sensor noise of this image.
  RenderedView Render(const Camera& camera, const geometry::Positions& V,
                      const geometry::Faces& F, const geometry::Positions& normals,
                      const geometry::Positions& rest, bool colour,
                      std::uint64_t noise_seed = 0) const;
  // Renders a subject with its environment (the mask covers the subject's faces only).
  RenderedView Render(const Camera& camera, const SceneView& scene, bool colour,
                      std::uint64_t noise_seed = 0) const;
  // The empty scene seen by `camera`: the backdrop, and `environment` (subject_face_count
  // 0) when given.
  cv::Mat RenderBackground(const Camera& camera, bool colour, std::uint64_t noise_seed = 0,
                           const SceneView* environment = nullptr) const;

 private:
  Eigen::Vector3d BackgroundRadiance(const Camera& camera, double x, double y) const;
  Eigen::Vector3d SampleRadiance(const SceneView& scene, const CanvasHit& hit, bool subject) const;
  cv::Mat Encode(const std::vector<Eigen::Vector3d>& radiance, int width, int height,
                 bool colour, std::uint64_t noise_seed) const;

  SyntheticRenderOptions options_;
  bool textured_background_ = false;
  ProceduralAlbedo albedo_, environment_albedo_;
};

// Direction towards the key light (the one that casts the soft shadows), unit.
Eigen::Vector3d KeyLightDirection();

struct SynthOptions {
  SyntheticSceneOptions scene;
  CameraRigOptions rig;
  SyntheticRenderOptions render;
  std::vector<int> colour_cameras = {0, 4};  // indices of colour cameras (others are gray)
  int colour_every = 0;       // > 0: camera k is colour when k % colour_every == 0 (overrides)
  std::uint32_t seed = 1;     // texture and noise
  double fps = 60.0;
  bool overwrite = false;     // replace the dataset in a non-empty output directory
  double bounds_margin = 0.1;  // bounds = object box over all frames grown by this × its size per side
  EnvironmentOptions environment;  // floor / room, distractors, soft shadows
  std::vector<double> distortion;  // k1 k2 p1 p2 k3 of every camera (empty = none)
  bool write_masks = true;         // masks/<cam>/<frame>.png
  bool write_background = true;    // background/<cam>.png (the clean plate)
  std::string video;               // "" = images/<cam>/<frame>.png; "mp4" = videos/<cam>.mp4 (mp4v)

  void Check() const;  // throws subflow::Error naming the option
  bool IsColourCamera(int camera) const;
};

struct SynthSummary {
  int camera_count = 0, frame_count = 0, vertex_count = 0, face_count = 0;
  Bounds bounds;
  double seconds = 0.0;        // whole run
  double render_seconds = 0.0;  // images + masks (rendering and PNG writing)
};

// Renders `options` into a new dataset directory (DatasetWriter: refuses a non-empty
// directory unless options.overwrite). Frame by frame, parallel over cameras (TBB);
// every file goes through core/atomic_file.h (videos: ".<cam>.partial.mp4", renamed when complete).
SynthSummary WriteSyntheticDataset(const std::string& directory, const SynthOptions& options,
                                   Progress* progress = nullptr);

}  // namespace subflow::vision
