// The stages as commands on stage folders (docs/stages.md): `subflow shape → motion →
// refine → retrack → split` gives what `subflow reconstruct` gives (to 1e-9, the floats
// of the result being the same), `reconstruct --resume` reuses the complete stage folders
// of an interrupted run and ends with the same result, and `refine --frames` ranges
// merged by `subflow merge` take each frame from the range that holds it most inside.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "geometry/mesh_io.h"
#include "output/stage_folder.h"
#include "tests/test_support.h"
#include "vision/dataset.h"
#include "vision/image_sequence.h"
#include "vision/working_scale.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;
using test::TemporaryDirectory;

const TemporaryDirectory& Scratch() {
  static const TemporaryDirectory scratch("stage_commands");
  return scratch;
}
std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// A small deforming blob: 6 gray cameras, 6 frames, 160×120.
const fs::path& Dataset() {
  static const fs::path dataset = [] {
    const fs::path path = Scratch() / "blob";
    const test::CommandResult run = RunSubflow(
        "synth blob --out " + Quoted(path) + " --cameras 6 --frames 6 --width 160 --height 120 --subdivisions 4 --gray",
        Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return path;
  }();
  return dataset;
}
const std::string kShape = " --base-faces 120 --levels 2 ";
const std::string kRefine = " --window 3 --iterations 4 ";

void RunOk(const std::string& arguments) {
  const test::CommandResult run = RunSubflow(arguments, Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << arguments << "\n" << run.output();
}

nlohmann::json ReadReport(const fs::path& folder) {
  return nlohmann::json::parse(test::ReadTextFile(folder / "report.json"));
}

// The largest difference of any vertex coordinate or property between the PLY files that
// `reference`/<subdirectory> holds and the same files in `candidate` (which must all exist,
// with the same faces); the number of files compared in *files.
double MaxDifference(const fs::path& reference, const fs::path& candidate, const std::string& subdirectory,
                     int* files) {
  double largest = 0;
  *files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(reference / subdirectory)) {
    if (entry.path().extension() != ".ply") continue;
    const fs::path other = candidate / fs::relative(entry.path(), reference);
    EXPECT_TRUE(fs::exists(other)) << other;
    if (!fs::exists(other)) return 1e300;
    geometry::VertexProperties a_properties, b_properties;
    const geometry::TriangleMesh a = geometry::ReadMesh(entry.path().string(), {}, &a_properties);
    const geometry::TriangleMesh b = geometry::ReadMesh(other.string(), {}, &b_properties);
    EXPECT_EQ(a.F, b.F) << other;
    EXPECT_EQ(a_properties.names, b_properties.names) << other;
    if (a.V.rows() != b.V.rows() || a_properties.names != b_properties.names) return 1e300;
    largest = std::max(largest, (a.V - b.V).cwiseAbs().maxCoeff());
    for (const auto& [name, values] : a_properties.values)
      largest = std::max(largest, (values - b_properties.values.at(name)).cwiseAbs().maxCoeff());
    ++*files;
  }
  return largest;
}

// `subflow reconstruct` on the dataset, once for the whole file.
const fs::path& Reconstructed() {
  static const fs::path out = [] {
    const fs::path path = Scratch().FreshPath("reconstructed");
    RunOk("reconstruct " + Quoted(Dataset()) + " --out " + Quoted(path) + kShape + kRefine);
    return path;
  }();
  return out;
}

TEST(StageCommands, TheChainOfStageCommandsGivesWhatReconstructGives) {
  const fs::path chain = Scratch().Subdirectory("chain");
  const std::string dataset = Quoted(Dataset());
  RunOk("shape " + dataset + " --out " + Quoted(chain / "shape") + kShape);
  RunOk("motion " + dataset + " --from " + Quoted(chain / "shape") + " --out " + Quoted(chain / "motion"));
  RunOk("refine " + dataset + " --from " + Quoted(chain / "motion") + " --out " + Quoted(chain / "refine") + kRefine);
  RunOk("retrack " + dataset + " --from " + Quoted(chain / "refine") + " --out " + Quoted(chain / "retrack"));
  RunOk("split " + dataset + " --from " + Quoted(chain / "retrack") + " --out " + Quoted(chain / "result"));

  int files = 0;
  EXPECT_LE(MaxDifference(Reconstructed(), chain / "result", "meshes", &files), 1e-9);
  EXPECT_EQ(files, 6);
  // Every stage handed on the same exact (double) control points.
  for (const char* stage : {"shape", "motion", "refine", "retrack"}) {
    EXPECT_EQ(MaxDifference(Reconstructed() / "stages", chain, stage, &files), 0.0) << stage;
    EXPECT_GE(files, 6) << stage;
    const nlohmann::json report = ReadReport(chain / stage);
    EXPECT_EQ(report["stage_layout_version"], 1) << stage;
    EXPECT_EQ(report["stage"], stage);
    EXPECT_EQ(report["frames"], (nlohmann::json{{"first", 0}, {"count", 6}})) << stage;
  }
  // The result's report carries every stage's figures.
  const nlohmann::json report = ReadReport(chain / "result");
  for (const char* section : {"shape_init", "motion_init", "refinement", "retrack", "rigid_motion", "flow"})
    EXPECT_TRUE(report.contains(section)) << section;
  EXPECT_EQ(report["retrack"]["options"]["hull_weight"], 0.25);
  EXPECT_EQ(report["retrack"]["options"]["step"]["highpass_sigma"], 0.7);
}

// Each motion pass offers its own flags: the retrack's hull weight and high-pass are
// --retrack-weight and --retrack-highpass (RetrackOptions sets them over the first pass's),
// so the retrack command refuses the first pass's rather than ignore them, and a value given
// reaches the retrack's report.
TEST(StageCommands, TheRetrackTakesItsOwnWeightAndHighPass) {
  const test::CommandResult motion = RunSubflow("motion --help", Scratch().path());
  const test::CommandResult retrack = RunSubflow("retrack --help", Scratch().path());
  for (const char* flag : {"--motion-highpass", "--hull-weight"}) {
    EXPECT_NE(motion.out.find(flag), std::string::npos) << flag;
    EXPECT_EQ(retrack.out.find(flag), std::string::npos) << flag;
  }
  for (const char* flag : {"--retrack-highpass", "--retrack-weight"}) {
    EXPECT_EQ(motion.out.find(flag), std::string::npos) << flag;
    EXPECT_NE(retrack.out.find(flag), std::string::npos) << flag;
  }
  const fs::path work = Scratch().Subdirectory("retrack_flags");
  const std::string from = " --from " + Quoted(Reconstructed() / "stages" / "refine");
  const test::CommandResult refused =
      RunSubflow("retrack " + Quoted(Dataset()) + from + " --out " + Quoted(work / "a") + " --motion-highpass 1",
                 Scratch().path());
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_FALSE(fs::exists(work / "a" / "report.json"));
  RunOk("retrack " + Quoted(Dataset()) + from + " --out " + Quoted(work / "b") + " --retrack-highpass 1.5");
  const nlohmann::json report = ReadReport(work / "b");
  EXPECT_EQ(report["options"]["retrack"]["step"]["highpass_sigma"], 1.5);
  EXPECT_EQ(report["retrack"]["options"]["step"]["highpass_sigma"], 1.5);
}

TEST(StageCommands, ResumeLoadsTheCompleteStagesAndEndsWithTheSameResult) {
  // An interrupted run: shape and motion finished; refine was killed while writing (its
  // files are there, its report.json is not); retrack and the result never started.
  const fs::path out = Scratch().FreshPath("interrupted");
  fs::copy(Reconstructed(), out, fs::copy_options::recursive);
  fs::remove(out / "stages" / "refine" / "report.json");
  fs::remove_all(out / "stages" / "retrack");
  for (const char* entry : {"meshes", "obj", "control", "hull", "report.json"}) fs::remove_all(out / entry);

  const std::string command = "reconstruct " + Quoted(Dataset()) + " --out " + Quoted(out) + kShape + kRefine;
  const test::CommandResult refused = RunSubflow(command, Scratch().path());
  EXPECT_EQ(refused.exit_code, 1) << "a non-empty --out without --resume or --overwrite";
  RunOk(command + " --resume");
  const nlohmann::json report = ReadReport(out);
  EXPECT_EQ(report["stages"], (nlohmann::json{{"shape", "loaded"}, {"motion", "loaded"}, {"refine", "computed"},
                                               {"retrack", "computed"}}));
  int files = 0;
  EXPECT_LE(MaxDifference(Reconstructed(), out, "meshes", &files), 1e-9);
  EXPECT_EQ(files, 6);

  // Other options for motion: shape is still reused, motion and every later stage rerun.
  RunOk(command + " --resume --hull-weight 0.4");
  EXPECT_EQ(ReadReport(out)["stages"], (nlohmann::json{{"shape", "loaded"}, {"motion", "computed"},
                                                        {"refine", "computed"}, {"retrack", "computed"}}));
  EXPECT_GT(MaxDifference(Reconstructed(), out, "meshes", &files), 1e-6);
}

TEST(StageCommands, RefinementRangesMergeIntoOneStageFolder) {
  const fs::path work = Scratch().Subdirectory("ranges");
  const fs::path motion = Reconstructed() / "stages" / "motion";
  const std::string dataset = Quoted(Dataset());
  RunOk("refine " + dataset + " --from " + Quoted(motion) + " --frames 0:4 --out " + Quoted(work / "a") + kRefine);
  RunOk("refine " + dataset + " --from " + Quoted(motion) + " --frames 2:6 --out " + Quoted(work / "b") + kRefine);
  EXPECT_EQ(ReadReport(work / "b")["frames"], (nlohmann::json{{"first", 2}, {"count", 4}}));
  RunOk("merge " + Quoted(work / "a") + " " + Quoted(work / "b") + " --out " + Quoted(work / "merged"));

  const nlohmann::json report = ReadReport(work / "merged");
  EXPECT_EQ(report["stage"], "refine");
  EXPECT_EQ(report["frames"], (nlohmann::json{{"first", 0}, {"count", 6}}));
  // Frame 2 is 2 frames inside a's range [0, 4) and at b's edge; frame 3 the other way.
  EXPECT_EQ(report["frame_sources"], (nlohmann::json{0, 0, 0, 1, 1, 1}));
  const auto control = [](const fs::path& folder, const char* frame) {
    return geometry::ReadMesh((folder / "control" / frame / "level_2.ply").string()).V;
  };
  EXPECT_EQ(control(work / "merged", "000002"), control(work / "a", "000002"));
  EXPECT_EQ(control(work / "merged", "000003"), control(work / "b", "000003"));
  EXPECT_NE(control(work / "a", "000003"), control(work / "b", "000003"));
  // The merged folder is a stage folder like any: split turns it into a result.
  RunOk("split " + dataset + " --from " + Quoted(work / "merged") + " --out " + Quoted(work / "result"));
  EXPECT_TRUE(fs::exists(work / "result" / "meshes" / "000005.ply"));

  // A gap is refused, naming the frame no input holds.
  RunOk("refine " + dataset + " --from " + Quoted(motion) + " --frames 5:6 --out " + Quoted(work / "c") + kRefine);
  const test::CommandResult gap = RunSubflow(
      "merge " + Quoted(work / "a") + " " + Quoted(work / "c") + " --out " + Quoted(work / "gap"), Scratch().path());
  EXPECT_EQ(gap.exit_code, 1);
  EXPECT_NE(gap.err.find("frame 4"), std::string::npos) << gap.output();
}

// A still set against a plain backdrop: the shape stage's silhouettes are the object's
// outlines, written to the stage folder (outlines/<camera>.png, listed in report.json), read
// back with it, and the later stages take them as the cameras' masks: tight outlines, the
// same pixels. A missing outline file is refused, naming it.
TEST(StageCommands, AStillOnAPlainBackdropHandsItsOutlinesToTheLaterStages) {
  const fs::path work = Scratch().Subdirectory("outlines");
  const fs::path dataset = work / "still";
  RunOk("synth sphere --out " + Quoted(dataset) +
        " --cameras 6 --frames 1 --width 160 --height 120 --no-masks --no-background");
  RunOk("shape " + Quoted(dataset) + " --out " + Quoted(work / "shape") + kShape);
  const nlohmann::json report = ReadReport(work / "shape");
  ASSERT_EQ(report["outlines"].size(), 6u) << report["outlines"];
  EXPECT_EQ(report["outlines"][0], "outlines/0.png");

  const vision::Dataset opened(dataset.string());
  const output::StageRecord record = output::ReadStageFolder((work / "shape").string(), "shape");
  ASSERT_EQ(record.state.outlines.size(), 6u);
  const vision::ImageSequence images = solver::StageImages(opened, record.state);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(images.tight_outline.at(k), 1) << "camera " << k;
    const cv::Mat silhouette = images.silhouette(k, 0);  // at the stages' working image scale
    const cv::Mat outline = vision::ResizeToCamera(record.state.outlines[k], images.cameras[k], true);
    ASSERT_EQ(silhouette.size(), outline.size());
    EXPECT_GT(cv::countNonZero(outline), 300) << "camera " << k;
    EXPECT_EQ(cv::countNonZero(silhouette != outline), 0) << "camera " << k;
  }

  fs::remove(work / "shape" / "outlines" / "3.png");
  try {
    output::ReadStageFolder((work / "shape").string(), "shape");
    FAIL() << "a stage folder without its outline file was read";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("3.png"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("outlines[3]"), std::string::npos) << error.what();
  }
}

// A dataset with background images and no masks: the later stages take each frame's
// background-image silhouette, recomputed as the shape stage made it, as the camera's mask
// (tight outlines); the shape stage folder keeps the options that make them.
TEST(StageCommands, BackgroundImageSilhouettesAreTheLaterStagesOutlines) {
  const fs::path work = Scratch().Subdirectory("background_outlines");
  const fs::path dataset = work / "take";
  RunOk("synth sphere --out " + Quoted(dataset) + " --cameras 6 --frames 3 --width 160 --height 120 --no-masks");
  RunOk("shape " + Quoted(dataset) + " --out " + Quoted(work / "shape") + kShape);
  const nlohmann::json report = ReadReport(work / "shape");
  ASSERT_TRUE(report.contains("background_outlines"));

  const vision::Dataset opened(dataset.string());
  const output::StageRecord record = output::ReadStageFolder((work / "shape").string(), "shape");
  ASSERT_TRUE(record.state.background_outlines.has_value());
  const vision::ImageSequence images = solver::StageImages(opened, record.state);
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(images.tight_outline.at(k), 1) << "camera " << k;
    for (int f = 0; f < 3; ++f) {
      const cv::Mat expected = vision::ResizeToCamera(
          vision::BackgroundImageSilhouette(opened, k, f, *record.state.background_outlines).mask, images.cameras[k],
          true);
      const cv::Mat silhouette = images.silhouette(k, f);
      ASSERT_EQ(silhouette.size(), expected.size());
      EXPECT_GT(cv::countNonZero(expected), 300) << "camera " << k << ", frame " << f;
      EXPECT_EQ(cv::countNonZero(silhouette != expected), 0) << "camera " << k << ", frame " << f;
    }
  }
  // Asked again (the refinement asks at every level): the kept silhouettes, the same pixels.
  for (int k = 5; k >= 0; --k)
    for (int f = 2; f >= 0; --f) {
      const cv::Mat expected = vision::ResizeToCamera(
          vision::BackgroundImageSilhouette(opened, k, f, *record.state.background_outlines).mask, images.cameras[k],
          true);
      const cv::Mat again = images.silhouette(k, f);
      ASSERT_EQ(again.size(), expected.size());
      ASSERT_EQ(again.type(), expected.type());
      EXPECT_EQ(cv::countNonZero(again != expected), 0) << "camera " << k << ", frame " << f << ", asked again";
    }
}

TEST(StageCommands, AnUnfinishedOrWrongStageFolderIsRefused) {
  const fs::path work = Scratch().Subdirectory("refused");
  const fs::path unfinished = work / "unfinished";
  fs::copy(Reconstructed() / "stages" / "shape", unfinished, fs::copy_options::recursive);
  fs::remove(unfinished / "report.json");
  const test::CommandResult run = RunSubflow(
      "motion " + Quoted(Dataset()) + " --from " + Quoted(unfinished) + " --out " + Quoted(work / "m"),
      Scratch().path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("did not finish"), std::string::npos) << run.output();
  EXPECT_FALSE(fs::exists(work / "m" / "report.json"));

  const test::CommandResult wrong = RunSubflow("refine " + Quoted(Dataset()) + " --from " +
                                                   Quoted(Reconstructed() / "stages" / "shape") + " --out " +
                                                   Quoted(work / "r"),
                                               Scratch().path());
  EXPECT_EQ(wrong.exit_code, 1);
  EXPECT_NE(wrong.err.find("expected \"motion\""), std::string::npos) << wrong.output();

  const test::CommandResult range = RunSubflow("refine " + Quoted(Dataset()) + " --from " +
                                                   Quoted(Reconstructed() / "stages" / "motion") +
                                                   " --frames 4:9 --out " + Quoted(work / "r2"),
                                               Scratch().path());
  EXPECT_EQ(range.exit_code, 1);
  EXPECT_NE(range.err.find("[4, 9) is not inside the frames [0, 6)"), std::string::npos) << range.output();
}

}  // namespace
}  // namespace subflow
