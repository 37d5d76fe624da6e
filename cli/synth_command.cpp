// `subflow synth SCENE --out DIR`: renders a synthetic multi-view video dataset with
// ground truth (vision/synthetic_render.h) in the layout of ../shared/DATASET.md.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "output/report.h"
#include "output/result_writer.h"
#include "vision/synthetic_render.h"

namespace subflow::cli {

Command AddSynthCommand(CLI::App& app) {
  auto options = std::make_shared<vision::SynthOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "synth", "Render a synthetic dataset with ground-truth meshes (blob, rigid, head, sphere, bust, mug, pair, critter)");
  command->add_option("scene", options->scene.scene,
                      "Scene: blob, rigid, head, sphere (icospheres) or bust, mug, pair, critter (SDF subjects)")
      ->required()
      ->check(CLI::IsMember(vision::SyntheticSceneNames()));
  command->add_option("--out,-o", *out, "Output dataset directory (new or empty)")->required();
  command->add_option("--cameras", options->rig.camera_count, "Number of cameras")
      ->capture_default_str();
  command->add_option("--rig", options->rig.rig, "Camera rig: ring, dome, partial-dome or front (front half only)")
      ->check(CLI::IsMember({"ring", "dome", "partial-dome", "front"}))
      ->capture_default_str();
  command->add_option("--width", options->rig.width, "Image width (px)")->capture_default_str();
  command->add_option("--height", options->rig.height, "Image height (px)")->capture_default_str();
  command->add_option("--focal", options->rig.focal, "Focal length (px); 0 = 420 × width / 320")
      ->capture_default_str();
  command->add_option("--distance", options->rig.distance, "Camera distance to the object (m)")
      ->capture_default_str();
  command->add_option("--frames", options->scene.frame_count, "Number of frames")->capture_default_str();
  command->add_option("--start-frame", options->scene.start_frame,
                      "Frame f shows the scene's frame start-frame + f (a still: --frames 1 --start-frame F)")
      ->capture_default_str();
  command->add_option("--voxel", options->scene.voxel_size,
                      "SDF subjects: meshing voxel (m); the 3 mm plates need <= 0.0015")
      ->capture_default_str();
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
  command->add_option("--environment", options->environment.kind,
                      "Around the subject: none, floor (textured) or room (textured floor and walls)")
      ->check(CLI::IsMember({"none", "floor", "room"}))
      ->capture_default_str();
  command->add_option("--distractors", options->environment.distractors,
                      "Moving things outside the working volume: none, walker, crosser (in front of cam00) or both")
      ->check(CLI::IsMember({"none", "walker", "crosser", "both"}))
      ->capture_default_str();
  command->add_flag("--shadows", options->environment.shadows, "Soft shadows of the subject from the key light");
  command->add_option("--distortion", options->distortion, "Lens distortion k1,k2,p1,p2,k3 of every camera")
      ->delimiter(',')
      ->expected(5);
  auto no_masks = std::make_shared<bool>(false), no_background = std::make_shared<bool>(false);
  command->add_flag("--no-masks", *no_masks, "Write no masks/ (ground truth is still written)");
  command->add_flag("--no-background", *no_background, "Write no background/ images");
  command->add_option("--video", options->video, "Write frames as videos/<cam>.mp4 (mp4v) instead of PNGs")
      ->check(CLI::IsMember({"mp4"}));
  command->add_option("--subdivisions", options->scene.subdivisions, "Icosphere levels of the mesh")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Texture and noise seed")->capture_default_str();
  auto all_gray = std::make_shared<bool>(false);
  command->add_flag("--gray", *all_gray, "Every camera gray (no colour cameras)")->excludes(colour_list);
  command->add_flag("--overwrite", options->overwrite, "Replace the dataset in a non-empty directory");

  return {command, [options, out, colour_list, all_gray, no_masks, no_background] {
            options->write_masks = !*no_masks;
            options->write_background = !*no_background;
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
            // Last, so that a dataset folder without it is visibly unfinished.
            output::WriteJsonFile(*out + "/report.json",
                                  {{"command", "synth"},
                                   {"arguments", InvocationArguments()},
                                   {"versions", output::VersionsJson()},
                                   {"scene", options->scene.scene},
                                   {"rig", options->rig.rig},
                                   {"cameras", summary.camera_count},
                                   {"frames", summary.frame_count},
                                   {"width", options->rig.width},
                                   {"height", options->rig.height},
                                   {"seed", options->seed},
                                   {"mesh", {{"vertices", summary.vertex_count}, {"faces", summary.face_count}}},
                                   {"bounds", {{"min", {summary.bounds.min.x(), summary.bounds.min.y(), summary.bounds.min.z()}},
                                               {"max", {summary.bounds.max.x(), summary.bounds.max.y(), summary.bounds.max.z()}}}},
                                   {"seconds", summary.seconds}});
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
