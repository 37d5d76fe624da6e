// `subflow synth SCENE --out DIR`: renders a synthetic multi-view video dataset with
// ground truth (vision/synthetic_render.h) in the layout of ../shared/DATASET.md.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "vision/synthetic_render.h"

namespace subflow::cli {

Command AddSynthCommand(CLI::App& app) {
  auto options = std::make_shared<vision::SynthOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "synth", "Render a synthetic dataset (blob, rigid, head or sphere) with ground-truth meshes");
  command->add_option("scene", options->scene.scene, "Scene: blob, rigid, head or sphere")
      ->required()
      ->check(CLI::IsMember(vision::SyntheticSceneNames()));
  command->add_option("--out,-o", *out, "Output dataset directory (new or empty)")->required();
  command->add_option("--cameras", options->rig.camera_count, "Number of cameras")
      ->capture_default_str();
  command->add_option("--rig", options->rig.rig, "Camera rig: ring, dome or partial-dome")
      ->check(CLI::IsMember({"ring", "dome", "partial-dome"}))
      ->capture_default_str();
  command->add_option("--width", options->rig.width, "Image width (px)")->capture_default_str();
  command->add_option("--height", options->rig.height, "Image height (px)")->capture_default_str();
  command->add_option("--focal", options->rig.focal, "Focal length (px); 0 = 420 × width / 320")
      ->capture_default_str();
  command->add_option("--distance", options->rig.distance, "Camera distance to the object (m)")
      ->capture_default_str();
  command->add_option("--frames", options->scene.frame_count, "Number of frames")->capture_default_str();
  command->add_option("--motion", options->scene.motion, "Motion per frame, relative to the scene's default")
      ->capture_default_str();
  command->add_option("--noise", options->render.noise_sigma, "Gaussian sensor noise σ (grey levels of 255)")
      ->capture_default_str();
  auto colour_list = command->add_option("--color-cameras", options->colour_cameras,
                                         "Indices of the colour cameras (default 0,4 where they exist)")
                         ->delimiter(',');
  command->add_option("--color-every", options->colour_every,
                      "Every k-th camera is colour (overrides --color-cameras; 0 = off)")
      ->capture_default_str();
  command->add_option("--supersample", options->render.supersample, "Anti-aliasing samples per pixel axis")
      ->capture_default_str();
  command->add_option("--background", options->render.background, "Background: dark or texture")
      ->check(CLI::IsMember({"dark", "texture"}))
      ->capture_default_str();
  command->add_option("--subdivisions", options->scene.subdivisions, "Icosphere levels of the mesh")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Texture and noise seed")->capture_default_str();
  auto all_gray = std::make_shared<bool>(false);
  command->add_flag("--gray", *all_gray, "Every camera gray (no colour cameras)")->excludes(colour_list);
  command->add_flag("--overwrite", options->overwrite, "Replace the dataset in a non-empty directory");

  return {command, [options, out, colour_list, all_gray] {
            if (*all_gray) {
              options->colour_cameras.clear();
            } else if (colour_list->count() == 0) {  // the defaults, where those cameras exist
              std::vector<int> present;
              for (int c : options->colour_cameras)
                if (c < options->rig.camera_count) present.push_back(c);
              options->colour_cameras = present;
            }
            ProgressBar progress;
            const vision::SynthSummary summary = vision::WriteSyntheticDataset(*out, *options, &progress);
            std::cout << "synth " << options->scene.scene << ": " << summary.camera_count << " cameras ("
                      << options->rig.rig << "), " << summary.frame_count << " frames, "
                      << options->rig.width << "x" << options->rig.height << ", mesh "
                      << summary.vertex_count << " vertices / " << summary.face_count << " triangles\n"
                      << "bounds: min [" << summary.bounds.min.transpose() << "] max ["
                      << summary.bounds.max.transpose() << "]\n"
                      << "written to " << *out << " in " << summary.seconds << " s (images "
                      << summary.render_seconds << " s)\n";
          }};
}

}  // namespace subflow::cli
