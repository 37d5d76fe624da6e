// Shape initialization (method §4.1) end to end, on rendered datasets of the `sphere`
// scene (vision/synthetic_scene.h), whose true surface is known exactly:
//   - on a convex object the visual hull contains the true surface and lies within a few
//     voxels of it (the claim of issue 4);
//   - bad input in the dataset (a camera that sees nothing of the volume, an empty
//     silhouette, an object leaving the bounds) gives a warning naming the camera, frame
//     or side, and the hulls are still computed from what remains; no evidence at all is
//     an error that says so.
#include "solver/shape/shape_init.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tbb/task_arena.h>
#include <opencv2/imgcodecs.hpp>

#include "geometry/closest_point.h"
#include "core/error.h"
#include "geometry/mesh_io.h"
#include "tests/test_support.h"
#include "vision/synthetic_render.h"

namespace subflow::solver {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("shape_init_test");
  return scratch;
}

vision::SynthOptions SphereOptions(const std::string& rig, int cameras, int width, int height, int frames) {
  vision::SynthOptions options;
  options.scene.scene = "sphere";
  options.scene.frame_count = frames;
  options.scene.subdivisions = 4;  // 2562 vertices; inscribed within 1e-4 m of the sphere
  options.rig.rig = rig;
  options.rig.camera_count = cameras;
  options.rig.width = width;
  options.rig.height = height;
  options.colour_cameras = {0};
  return options;
}

// Fast settings for the later stages, which these tests do not measure.
ShapeInitOptions QuickOptions() {
  ShapeInitOptions options;
  options.levels = 1;
  options.simplify.target_face_count = 100;
  return options;
}

// The voxel edge of frame `frame`'s carving (cubic voxels over the longest side).
double VoxelSize(const vision::Dataset& dataset, const FrameShapeInit& frame) {
  return dataset.bounds().Size().maxCoeff() / frame.carving.resolution;
}

struct SphereFit {
  Eigen::Vector3d centre;
  double radius = 0;
};
// The true sphere at `frame`: centre = mean of the ground-truth icosphere's vertices.
SphereFit TrueSphere(const vision::Dataset& dataset, int frame) {
  const geometry::TriangleMesh mesh = geometry::ReadMesh(dataset.GroundTruthMeshPath(frame));
  SphereFit sphere;
  sphere.centre = mesh.V.colwise().mean();
  sphere.radius = (mesh.V.rowwise() - sphere.centre.transpose()).rowwise().norm().mean();
  return sphere;
}

// Every ground-truth vertex inside the hull (all but `max_outside_fraction` of them);
// returns the Hausdorff distance between the hull and the true sphere (hull vertices to
// the analytic sphere, true vertices to the hull).
double ExpectContainsTruthAndHausdorff(const vision::Dataset& dataset, const FrameShapeInit& frame,
                                       double max_outside_fraction = 0.0) {
  const geometry::TriangleMesh truth = geometry::ReadMesh(dataset.GroundTruthMeshPath(frame.frame));
  const SphereFit sphere = TrueSphere(dataset, frame.frame);
  const geometry::ClosestPointTree hull(frame.hull, "hull");
  int outside = 0;
  for (Eigen::Index i = 0; i < truth.V.rows(); ++i)
    outside += hull.Side(truth.V.row(i).transpose()) == geometry::PointSide::kOutside;
  EXPECT_LE(outside, max_outside_fraction * truth.V.rows())
      << "of " << truth.V.rows() << " true vertices outside the hull of frame " << frame.frame;
  double hausdorff = hull.Distances(truth.V).maxCoeff();
  for (Eigen::Index i = 0; i < frame.hull.V.rows(); ++i)
    hausdorff = std::max(hausdorff, std::abs((frame.hull.V.row(i).transpose() - sphere.centre).norm() - sphere.radius));
  return hausdorff;
}

// A convex object: its visual hull contains it, and (conservative carving, vision/
// voxel_carving.h) lies outside the exact visual hull by at most ~(√3/2 + ½) voxel + 1 px;
// with a 10-camera dome at ~2 px per voxel the exact hull of a sphere bulges by about a
// voxel between the cones. Claim: Hausdorff(hull, truth) ≤ 3 voxels.
TEST(ShapeInit, HullOfAConvexObjectContainsItAndLiesWithinThreeVoxels) {
  const fs::path directory = Scratch().FreshPath("convex");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 10, 160, 120, 2));
  const vision::Dataset dataset(directory.string());
  const ShapeInitResult result = InitializeShape(dataset, QuickOptions());
  ASSERT_EQ(result.frames.size(), 2u);
  for (const FrameShapeInit& frame : result.frames) {
    EXPECT_TRUE(frame.carving.warnings.empty()) << frame.carving.warnings.front();
    const double voxel = VoxelSize(dataset, frame);
    const double hausdorff = ExpectContainsTruthAndHausdorff(dataset, frame);
    std::printf("[ figures ] frame %d: %d voxels along the longest axis (%.2f mm), Hausdorff %.2f mm = %.2f voxels, "
                "mean silhouette IoU %.4f\n",
                frame.frame, frame.carving.resolution, 1e3 * voxel, 1e3 * hausdorff, hausdorff / voxel,
                frame.carving.mean_silhouette_iou);
    EXPECT_LE(hausdorff, 3.0 * voxel) << "frame " << frame.frame;
  }
}

// Carving hollows by free space (vision/concavity_carving.h) on this untextured sphere:
// its depths come from shading alone, and without the surface veto 337-372 of its 2,562
// true vertices fall outside the carved hull; with it the hull still holds the sphere.
TEST(ShapeInit, CarvingHollowsKeepsAConvexObjectInsideItsHull) {
  const fs::path directory = Scratch().FreshPath("convex_concavities");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 10, 160, 120, 2));
  const vision::Dataset dataset(directory.string());
  ShapeInitOptions options = QuickOptions();
  options.concavities.enabled = true;
  const ShapeInitResult result = InitializeShape(dataset, options);
  for (const FrameShapeInit& frame : result.frames) {
    EXPECT_GT(frame.concavities.trusted_pixels, 0) << "frame " << frame.frame << ": " << frame.concavities.skipped;
    EXPECT_LE(ExpectContainsTruthAndHausdorff(dataset, frame), 3.0 * VoxelSize(dataset, frame));
  }
}

// Mean distance of the hull's vertices from the true sphere (outside positive).
double MeanExcess(const vision::Dataset& dataset, const FrameShapeInit& frame) {
  const SphereFit sphere = TrueSphere(dataset, frame.frame);
  return ((frame.hull.V.rowwise() - sphere.centre.transpose()).rowwise().norm().array() - sphere.radius).mean();
}

// The claim of a hull from measured silhouettes against the hull of the masks (the test
// below says why these bounds): it contains the sphere, its Hausdorff distance is ≤ 3
// voxels, and its mean excess over the sphere ≤ 1.5 × the masks' plus a quarter voxel.
void ExpectAsCloseAsTheMaskHull(const vision::Dataset& dataset, const FrameShapeInit& frame,
                                const vision::Dataset& with_masks, const FrameShapeInit& mask_frame,
                                const char* what) {
  const double voxel = VoxelSize(dataset, frame);
  const double hausdorff = ExpectContainsTruthAndHausdorff(dataset, frame, 0.005);
  const double excess = MeanExcess(dataset, frame), mask_excess = MeanExcess(with_masks, mask_frame);
  std::printf("[ figures ] frame %d: %s hull: Hausdorff %.2f voxels, mean excess %.3f voxels (masks: %.3f), "
              "mean silhouette IoU %.4f\n",
              frame.frame, what, hausdorff / voxel, excess / voxel, mask_excess / voxel,
              frame.carving.mean_silhouette_iou);
  EXPECT_LE(hausdorff, 3.0 * voxel) << what << ", frame " << frame.frame;
  EXPECT_LE(excess, 1.5 * mask_excess + 0.25 * voxel) << what << ", frame " << frame.frame;
}

// Without masks, the background difference gives a hull as close as the masks' (the
// silhouettes match the masks to ~½ pixel, and the strict hull, max_misses = 0, is carved
// from them): same claim (contains the sphere, Hausdorff ≤ 3 voxels), and a mean excess
// over the sphere within 1.5 × the masks' plus a quarter voxel. The silhouettes' contours
// are estimated, not given: a few true vertices (≤ 0.5 %) may fall just outside.
// This is the plain difference's claim (background_shadow_test off). The default,
// shadow-robust difference does not keep it on this untextured sphere: a shaded side
// darker than the background by about one gain reads as shadow, and 131 of 2,562 true
// vertices fall outside its hull (mean excess 0.65 voxels against the masks' 0.71);
// what it gains on textured floors and shadows is measured on the scenes (the note of
// issue 12) and in VoxelCarvingBlob.FromShadowRobustDifferenceIsTighterAndHoldsTheObject.
TEST(ShapeInit, HullFromPlainBackgroundDifferenceIsAsCloseAsTheHullFromMasks) {
  const fs::path directory = Scratch().FreshPath("background_only");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 10, 160, 120, 2));
  const vision::Dataset with_masks(directory.string());
  const ShapeInitResult from_masks = InitializeShape(with_masks, QuickOptions());
  fs::remove_all(directory / "masks");
  const vision::Dataset dataset(directory.string());
  ShapeInitOptions plain = QuickOptions();
  plain.silhouettes.background_shadow_test = false;
  const ShapeInitResult result = InitializeShape(dataset, plain);
  ASSERT_EQ(result.frames.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const FrameShapeInit& frame = result.frames[i];
    ASSERT_EQ(frame.carving.cameras.front().source, vision::EvidenceSource::kBackground);
    EXPECT_EQ(frame.carving.max_misses, 0);
    ExpectAsCloseAsTheMaskHull(dataset, frame, with_masks, from_masks.frames[i], "background");
  }
}

// A small ring dataset with masks (5 cameras, 96×72, 3 frames), copied per variant.
const fs::path& BaseDataset() {
  static const fs::path directory = [] {
    const fs::path path = Scratch().FreshPath("base");
    vision::WriteSyntheticDataset(path.string(), SphereOptions("ring", 5, 96, 72, 3));
    return path;
  }();
  return directory;
}

fs::path CopyOfBase(const std::string& name) {
  const fs::path copy = Scratch().FreshPath(name);
  fs::copy(BaseDataset(), copy, fs::copy_options::recursive);
  return copy;
}

nlohmann::json ReadJson(const fs::path& path) { return nlohmann::json::parse(test::ReadTextFile(path)); }
void WriteJson(const fs::path& path, const nlohmann::json& json) { std::ofstream(path) << json.dump(1); }

bool AnyContains(const std::vector<std::string>& texts, const std::string& part) {
  for (const std::string& text : texts)
    if (text.find(part) != std::string::npos) return true;
  return false;
}

TEST(ShapeInitBadInput, CameraThatSeesNothingIsExcludedAndTheHullIsStillComputed) {
  // cam00 turned around on the spot (180° about its y axis): it sees only the wall behind.
  const fs::path directory = CopyOfBase("away");
  nlohmann::json cameras = ReadJson(directory / "cameras.json");
  nlohmann::json away = cameras["cameras"][0];
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int r = 0; r < 3; ++r) {
    t(r) = away["t"][r].get<double>();
    for (int c = 0; c < 3; ++c) R(r, c) = away["R"][r][c].get<double>();
  }
  const Eigen::Vector3d centre = -R.transpose() * t;
  const Eigen::Matrix3d turned = Eigen::Vector3d(-1, 1, -1).asDiagonal() * R;
  const Eigen::Vector3d turned_t = -turned * centre;
  for (int r = 0; r < 3; ++r) {
    away["t"][r] = turned_t(r);
    for (int c = 0; c < 3; ++c) away["R"][r][c] = turned(r, c);
  }
  away["name"] = "away";
  cameras["cameras"].push_back(away);
  WriteJson(directory / "cameras.json", cameras);
  for (const char* folder : {"images", "masks"})
    fs::copy(directory / folder / "cam00", directory / folder / "away", fs::copy_options::recursive);
  fs::copy_file(directory / "background" / "cam00.png", directory / "background" / "away.png");

  const vision::Dataset dataset(directory.string());
  const ShapeInitResult result = InitializeShape(dataset, QuickOptions());
  ASSERT_EQ(result.frames.size(), 3u);
  for (const FrameShapeInit& frame : result.frames) {
    EXPECT_TRUE(AnyContains(frame.carving.warnings, "camera \"away\" sees nothing of the working volume"))
        << "frame " << frame.frame;
    ASSERT_EQ(frame.carving.cameras.size(), 6u);
    EXPECT_FALSE(frame.carving.cameras.back().used);
    EXPECT_EQ(frame.carving.cameras.back().excluded, "sees nothing of the working volume");
    ExpectContainsTruthAndHausdorff(dataset, frame);
  }
}

TEST(ShapeInitBadInput, EmptySilhouetteIsExcludedForItsFrameOnly) {
  const fs::path directory = CopyOfBase("empty");
  const cv::Mat empty = cv::Mat::zeros(72, 96, CV_8UC1);
  cv::imwrite((directory / "masks" / "cam01" / "000001.png").string(), empty);
  const vision::Dataset dataset(directory.string());
  const ShapeInitResult result = InitializeShape(dataset, QuickOptions());
  ASSERT_EQ(result.frames.size(), 3u);
  for (const FrameShapeInit& frame : result.frames) {
    const bool broken = frame.frame == 1;
    EXPECT_EQ(AnyContains(frame.carving.warnings, "frame 1: camera \"cam01\" has an empty silhouette"), broken);
    EXPECT_EQ(frame.carving.cameras[1].used, !broken);
    // The four other cameras still carve; containment holds (a hull from fewer views is larger).
    ExpectContainsTruthAndHausdorff(dataset, frame);
  }
}

TEST(ShapeInitBadInput, ObjectLeavingTheBoundsIsReportedAndTheRestIsComputed) {
  // The bounds cut the sphere at +x: the hull is cut there, and every frame says so.
  const fs::path directory = CopyOfBase("cut");
  nlohmann::json cameras = ReadJson(directory / "cameras.json");
  const vision::Dataset original(BaseDataset().string());
  const double cut = TrueSphere(original, 0).centre.x() + 0.05;
  cameras["bounds"]["max"][0] = cut;
  WriteJson(directory / "cameras.json", cameras);
  const vision::Dataset dataset(directory.string());
  const ShapeInitResult result = InitializeShape(dataset, QuickOptions());
  ASSERT_EQ(result.frames.size(), 3u);
  for (const FrameShapeInit& frame : result.frames) {
    EXPECT_TRUE(AnyContains(frame.carving.warnings, "the object touches the +x side")) << "frame " << frame.frame;
    EXPECT_GT(frame.carving.border_voxels[1], 0u);
    EXPECT_GT(frame.hull.face_count(), 100);
    // Closed off at the bounds: the iso-surface at ½ between the last occupied voxel
    // centres and the empty padding, within a voxel of the cut.
    EXPECT_LE(frame.hull.V.col(0).maxCoeff(), cut + VoxelSize(dataset, frame));
  }
  EXPECT_GT(result.base_mesh.face_count(), 0);
}

// Frames 0 and 1 show the same images as frame 2 (the object waits, then moves), without
// masks or background: with a motion window of 0, frames 0 and 1 see no motion at all.
// They get a warning naming them and the hull of frame 2, the nearest frame with
// evidence; frames 2..4 are carved from their own motion evidence.
TEST(ShapeInitBadInput, FrameWithoutMasksAndMotionTakesTheHullOfItsNearestFrameWithEvidence) {
  const fs::path directory = Scratch().FreshPath("waits");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("ring", 5, 96, 72, 5));
  fs::remove_all(directory / "masks");
  fs::remove_all(directory / "background");
  for (const auto& camera : fs::directory_iterator(directory / "images"))
    for (const char* frame : {"000000.png", "000001.png"})
      fs::copy_file(camera.path() / "000002.png", camera.path() / frame, fs::copy_options::overwrite_existing);
  const vision::Dataset dataset(directory.string());
  ShapeInitOptions options = QuickOptions();
  options.silhouettes.motion_window = 0;
  options.silhouettes.estimate_background = false;  // motion evidence itself (not a background from it)
  options.reference_frame = 3;
  const ShapeInitResult result = InitializeShape(dataset, options);
  ASSERT_EQ(result.frames.size(), 5u);
  for (const FrameShapeInit& frame : result.frames) {
    const bool waits = frame.frame < 2;
    EXPECT_EQ(frame.hull_from_frame, waits ? 2 : frame.frame);
    EXPECT_EQ(AnyContains(frame.carving.warnings, "frame " + std::to_string(frame.frame) +
                                                      ": no masks, no background, and motion evidence in fewer"),
              waits)
        << "frame " << frame.frame;
    EXPECT_GT(frame.hull.face_count(), 100) << "frame " << frame.frame;
    ASSERT_FALSE(frame.control.empty());
  }
  EXPECT_EQ(result.frames[0].hull.V, result.frames[2].hull.V);
  EXPECT_EQ(result.frames[1].hull.V, result.frames[2].hull.V);
}

// Mean IoU over cameras of `silhouettes` against the true masks of `truth` at `frame`.
double MeanIouAgainstMasks(const std::vector<vision::Silhouette>& silhouettes, const vision::Dataset& truth,
                           int frame) {
  double sum = 0;
  for (int c = 0; c < truth.camera_count(); ++c) {
    const cv::Mat mask = truth.Mask(c, frame) != 0, found = silhouettes[c].mask != 0;
    const int intersection = cv::countNonZero(mask & found), united = cv::countNonZero(mask | found);
    sum += united > 0 ? static_cast<double>(intersection) / united : 1.0;
  }
  return sum / truth.camera_count();
}

// Without masks and background, the background estimated from the video (median over
// the frames where motion evidence leaves a pixel free) gives silhouettes closer to
// the true masks than raw motion evidence, which fires only where texture moves.
TEST(ShapeInit, BackgroundEstimatedFromTheVideoGivesBetterSilhouettesThanMotionEvidence) {
  const fs::path truth_directory = Scratch().FreshPath("estimate_truth");
  vision::SynthOptions synth;
  synth.scene.scene = "blob";
  synth.scene.frame_count = 8;
  synth.rig.rig = "ring";
  synth.rig.camera_count = 4;
  synth.rig.width = 240;
  synth.rig.height = 180;
  synth.render.supersample = 2;
  synth.colour_cameras = {0};
  vision::WriteSyntheticDataset(truth_directory.string(), synth);
  const fs::path directory = Scratch().FreshPath("estimate");
  fs::copy(truth_directory, directory, fs::copy_options::recursive);
  fs::remove_all(directory / "masks");
  fs::remove_all(directory / "background");
  const vision::Dataset truth(truth_directory.string()), dataset(directory.string());

  vision::SilhouetteOptions options;
  const std::vector<vision::EstimatedBackground> estimated = vision::EstimateBackgrounds(dataset, options);
  ASSERT_EQ(static_cast<int>(estimated.size()), dataset.camera_count());
  double estimated_iou = 0, motion_iou = 0;
  for (int frame = 0; frame < dataset.frame_count(); ++frame) {
    const auto from_background = vision::ComputeFrameEvidence(dataset, frame, options, &estimated);
    const auto from_motion = vision::ComputeFrameEvidence(dataset, frame, options);
    for (int c = 0; c < dataset.camera_count(); ++c) {
      EXPECT_EQ(from_background[c].source, vision::EvidenceSource::kBackground);
      EXPECT_EQ(from_motion[c].source, vision::EvidenceSource::kMotion);
    }
    estimated_iou += MeanIouAgainstMasks(from_background, truth, frame) / dataset.frame_count();
    motion_iou += MeanIouAgainstMasks(from_motion, truth, frame) / dataset.frame_count();
  }
  for (const vision::EstimatedBackground& background : estimated) {
    EXPECT_EQ(background.frames, dataset.frame_count());
    EXPECT_GT(background.known_fraction, 0.5);
  }
  std::printf("mean silhouette IoU vs the true masks: estimated background %.4f, motion evidence %.4f\n",
              estimated_iou, motion_iou);
  // Measured: 0.954 from the estimated background, 0.929 from motion evidence.
  constexpr double kFloor = 0.945;
  EXPECT_GT(estimated_iou, kFloor);
  EXPECT_LT(motion_iou, kFloor);

  // InitializeShape estimates the backgrounds itself and keeps their figures.
  ShapeInitOptions quick = QuickOptions();
  quick.frame_count = 2;
  const ShapeInitResult result = InitializeShape(dataset, quick);
  ASSERT_EQ(static_cast<int>(result.estimated_backgrounds.size()), dataset.camera_count());
  EXPECT_EQ(result.estimated_backgrounds[0].frames, dataset.frame_count());
  EXPECT_EQ(result.frames[0].carving.cameras[0].source, vision::EvidenceSource::kBackground);
}

// A still set of one frame without masks or background, photographed against a plain
// backdrop (the synthetic scenes' dark one): every camera's backdrop is found plain and the
// hull is carved from the differences to its colour, as close to the sphere as the hull of
// the masks. (Without the backdrop, the photo-consistency of vision/still_evidence.h reads
// such sets badly or not at all: the next test, and docs/shape.md, "Still sets on a plain
// backdrop".)
TEST(ShapeInit, StillSetOnAPlainBackdropIsCarvedFromTheBackdropsColour) {
  const fs::path directory = Scratch().FreshPath("still_backdrop");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 10, 160, 120, 1));
  const vision::Dataset with_masks(directory.string());
  const ShapeInitResult from_masks = InitializeShape(with_masks, QuickOptions());
  fs::remove_all(directory / "masks");
  fs::remove_all(directory / "background");
  const vision::Dataset dataset(directory.string());
  const ShapeInitResult result = InitializeShape(dataset, QuickOptions());
  ASSERT_TRUE(result.used_still);
  ASSERT_TRUE(result.used_backdrop);
  ASSERT_EQ(result.backdrops.size(), 10u);
  for (const vision::PlainBackdrop& backdrop : result.backdrops) EXPECT_TRUE(backdrop.plain);
  const FrameShapeInit& frame = result.frames.at(0);
  EXPECT_EQ(frame.carving.cameras.front().source, vision::EvidenceSource::kStill);
  ExpectAsCloseAsTheMaskHull(dataset, frame, with_masks, from_masks.frames[0], "plain backdrop");
  // Against a plain backdrop the silhouettes are the object's outlines: carved as masks
  // are (no cleaning of the hull), and handed on for the refinement to take as masks.
  EXPECT_EQ(frame.carving.closing_radius, 0);
  EXPECT_EQ(frame.carving.opening_radius, 0);
  ASSERT_EQ(result.outlines.size(), 10u);
  for (int k = 0; k < 10; ++k) {
    const cv::Mat& outline = result.outlines[k];
    ASSERT_EQ(outline.type(), CV_8UC1);
    const cv::Mat truth = with_masks.Mask(k, 0);
    ASSERT_EQ(outline.size(), truth.size());
    EXPECT_GT(vision::SilhouetteIoU(outline, truth), 0.95) << "camera " << k;
  }
  EXPECT_TRUE(from_masks.outlines.empty());
}

// A still set that neither the backdrop (here turned off: the synthetic backdrop is plain)
// nor the photo-consistency fallback (vision/still_evidence.h) can read (a sphere of
// 96×72 px seen by 4 cameras: no trusted depths) is an error that says what was tried.
TEST(ShapeInitBadInput, NoMasksNoBackgroundNoMotionAndNoPhotoConsistencyIsAnErrorThatSaysSo) {
  const fs::path directory = Scratch().FreshPath("static");
  vision::SynthOptions options = SphereOptions("ring", 4, 96, 72, 3);
  options.scene.motion = 0.0;
  vision::WriteSyntheticDataset(directory.string(), options);
  fs::remove_all(directory / "masks");
  fs::remove_all(directory / "background");
  const vision::Dataset dataset(directory.string());
  ShapeInitOptions no_backdrop = QuickOptions();
  no_backdrop.still.backdrop.enabled = false;
  try {
    InitializeShape(dataset, no_backdrop);
    FAIL() << "a static dataset without masks or background gave a shape";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("no masks, no background, nothing moves, and the photo-consistency"),
              std::string::npos)
        << error.what();
  }
}

// A ShapeFrameStore that keeps what it is given and counts the hulls read back.
class RecordingStore : public ShapeFrameStore {
 public:
  void StoreHull(int frame, const geometry::TriangleMesh& hull) override { hulls[frame] = hull; }
  geometry::TriangleMesh LoadHull(int frame) const override {
    ++loads[frame];
    return hulls.at(frame);
  }
  void StoreControl(int frame, const geometry::LoopHierarchy&, const std::vector<geometry::Positions>& levels) override {
    EXPECT_EQ(control.count(frame), 0u) << "frame " << frame << " fitted twice";
    control[frame] = levels;
  }
  std::map<int, geometry::TriangleMesh> hulls;
  std::map<int, std::vector<geometry::Positions>> control;
  mutable std::map<int, int> loads;
};

// With a store (what the `shape` command gives to keep its memory independent of the
// take's length), every frame's hull and fit go to the store and none stays in the
// result, whose figures still give the hulls' sizes; the values are exactly those of the
// run without a store (the same frames fitted from the same neighbours, outwards from the
// reference frame, which only the two last fitted bases make possible); each hull is read
// back once for its fit, the reference frame's once more for the base mesh.
TEST(ShapeInit, AFrameStoreReceivesEveryHullAndFitWithTheSameValues) {
  const fs::path directory = Scratch().FreshPath("store");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 6, 160, 120, 5));
  const vision::Dataset dataset(directory.string());
  const ShapeInitResult in_memory = InitializeShape(dataset, QuickOptions());
  RecordingStore store;
  const ShapeInitResult stored = InitializeShape(dataset, QuickOptions(), nullptr, &store);
  ASSERT_EQ(stored.frames.size(), 5u);
  ASSERT_EQ(in_memory.frames.size(), 5u);
  EXPECT_EQ(stored.reference_frame, 2);
  for (std::size_t i = 0; i < stored.frames.size(); ++i) {
    const FrameShapeInit& frame = stored.frames[i];
    const FrameShapeInit& expected = in_memory.frames[i];
    EXPECT_EQ(frame.hull.vertex_count(), 0) << "frame " << frame.frame;
    EXPECT_TRUE(frame.control.empty()) << "frame " << frame.frame;
    ASSERT_EQ(store.hulls.count(frame.frame), 1u);
    EXPECT_EQ(store.hulls[frame.frame].V, expected.hull.V) << "frame " << frame.frame;
    EXPECT_EQ(store.hulls[frame.frame].F, expected.hull.F) << "frame " << frame.frame;
    EXPECT_EQ(frame.hull_vertices, expected.hull.vertex_count());
    EXPECT_EQ(frame.hull_faces, expected.hull.face_count());
    EXPECT_EQ(store.control[frame.frame], expected.control) << "frame " << frame.frame;
    EXPECT_EQ(store.loads[frame.frame], frame.frame == stored.reference_frame ? 2 : 1) << "frame " << frame.frame;
  }
  EXPECT_EQ(stored.base_mesh.F, in_memory.base_mesh.F);
  EXPECT_EQ(stored.reference_control, in_memory.frames[2].control.back());
}

// Frames are carved, meshed and fitted side by side (the iso-surfaces of consecutive
// frames, the fits of the two sides of the reference frame): every hull, fit and figure is
// exactly what one thread computes frame after frame.
TEST(ShapeInit, FramesSideBySideGiveExactlyWhatOneThreadGives) {
  const fs::path directory = Scratch().FreshPath("threads");
  vision::WriteSyntheticDataset(directory.string(), SphereOptions("dome", 6, 160, 120, 7));
  const vision::Dataset dataset(directory.string());
  ShapeInitResult one_thread;
  tbb::task_arena(1).execute([&] { one_thread = InitializeShape(dataset, QuickOptions()); });
  const ShapeInitResult side_by_side = InitializeShape(dataset, QuickOptions());
  ASSERT_EQ(side_by_side.frames.size(), 7u);
  ASSERT_EQ(one_thread.frames.size(), 7u);
  for (std::size_t i = 0; i < side_by_side.frames.size(); ++i) {
    const FrameShapeInit& frame = side_by_side.frames[i];
    const FrameShapeInit& expected = one_thread.frames[i];
    ASSERT_GT(frame.hull.vertex_count(), 0) << "frame " << frame.frame;
    EXPECT_EQ(frame.hull.V, expected.hull.V) << "frame " << frame.frame;
    EXPECT_EQ(frame.hull.F, expected.hull.F) << "frame " << frame.frame;
    EXPECT_EQ(frame.control, expected.control) << "frame " << frame.frame;
    EXPECT_EQ(frame.carving.carved_voxels, expected.carving.carved_voxels) << "frame " << frame.frame;
    EXPECT_EQ(frame.registration.iterations, expected.registration.iterations) << "frame " << frame.frame;
  }
  EXPECT_EQ(side_by_side.reference_control, one_thread.reference_control);
  EXPECT_GT(side_by_side.seconds, 0.0);
}

}  // namespace
}  // namespace subflow::solver
