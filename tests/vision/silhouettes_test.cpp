// Claims of vision/silhouettes.h: masks are taken as given; the background difference with
// Otsu's threshold recovers a drawn object; motion evidence (eq. 23) is positive where
// texture moves and zero where nothing changes; a dataset without masks, background or
// motion is an error that says so.
#include "vision/silhouettes.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "vision/dataset.h"
#include "vision/dataset_writer.h"
#include "vision/voxel_carving.h"
#include "tests/test_support.h"

namespace subflow::vision {
namespace {

// A smooth random texture in [0.2, 0.8] (features of a few pixels), CV_32F.
cv::Mat Texture(int width, int height, unsigned seed, double feature_sigma = 1.5) {
  cv::Mat noise(height, width, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(), feature_sigma);
  cv::normalize(noise, noise, 0.2, 0.8, cv::NORM_MINMAX);
  return noise;
}

cv::Mat AddNoise(const cv::Mat& image, double sigma, unsigned seed) {
  cv::Mat noise(image.size(), image.type());
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  return image + noise;
}

TEST(Silhouettes, MaskIsTakenAsGiven) {
  cv::Mat mask = cv::Mat::zeros(60, 80, CV_8UC1);
  cv::circle(mask, cv::Point(40, 30), 15, cv::Scalar(7), cv::FILLED);  // any non-zero = object
  const Silhouette silhouette = SilhouetteFromMask(mask);
  EXPECT_EQ(silhouette.source, EvidenceSource::kMask);
  EXPECT_EQ(silhouette.object_pixels, cv::countNonZero(mask));
  EXPECT_FALSE(silhouette.empty);
  // Exact: evidence is 1 on the mask and 0 elsewhere.
  EXPECT_EQ(cv::countNonZero(silhouette.mask != (mask != 0)), 0);
  EXPECT_EQ(cv::sum(silhouette.evidence)[0], silhouette.object_pixels);
  EXPECT_EQ(cv::countNonZero(silhouette.evidence), silhouette.object_pixels);
  EXPECT_TRUE(SilhouetteFromMask(cv::Mat::zeros(60, 80, CV_8UC1)).empty);
  EXPECT_THROW(SilhouetteFromMask(cv::Mat::zeros(60, 80, CV_32F)), Error);
}

TEST(Silhouettes, OtsuSeparatesTwoLevels) {
  cv::Mat image(40, 40, CV_32F, cv::Scalar(0.1));
  image(cv::Rect(0, 0, 40, 10)).setTo(0.7);
  const double t = OtsuThreshold(AddNoise(image, 0.02, 3));
  // Any threshold strictly between the two levels (± 3σ of the noise) separates them.
  EXPECT_GT(t, 0.1 + 0.06);
  EXPECT_LT(t, 0.7 - 0.06);
  EXPECT_FLOAT_EQ(OtsuThreshold(cv::Mat(5, 5, CV_32F, cv::Scalar(0.3))), 0.3f);  // constant image
}

// A background-difference-like histogram: 80 % noise |N(0, 0.01)|, 20 % object spread
// uniformly over [0.05, 0.6]. The triangle threshold sits at the foot of the noise peak
// (≈ 3σ of the noise = 0.03, below the object's lowest 0.05); Otsu splits the object.
TEST(Silhouettes, TriangleFindsTheFootOfTheNoisePeakWhereOtsuSplitsTheObject) {
  cv::Mat values(100, 100, CV_32F);
  cv::RNG rng(9);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x)
      values.at<float>(y, x) = y < 80 ? std::abs(static_cast<float>(rng.gaussian(0.01)))
                                      : static_cast<float>(rng.uniform(0.05, 0.6));
  const double triangle = TriangleThreshold(values);
  std::printf("[ figures ] triangle %.4f, Otsu %.4f\n", triangle, OtsuThreshold(values));
  EXPECT_GT(triangle, 0.015);
  EXPECT_LT(triangle, 0.05);
  EXPECT_GT(OtsuThreshold(values), 0.1);
}

// A bright disk in front of a textured background, in colour, with sensor noise.
TEST(Silhouettes, BackgroundDifferenceWithAutomaticThresholdRecoversDrawnDisk) {
  const int width = 160, height = 120;
  std::vector<cv::Mat> channels = {Texture(width, height, 1), Texture(width, height, 2),
                                   Texture(width, height, 3)};
  cv::Mat background;
  cv::merge(channels, background);
  cv::Mat image = background.clone();
  cv::Mat truth = cv::Mat::zeros(height, width, CV_8UC1);
  cv::circle(truth, cv::Point(80, 60), 35, cv::Scalar(255), cv::FILLED);
  image.setTo(cv::Scalar(0.95, 0.9, 0.1), truth);
  // An interior patch the colour of the background behind it: a hole that must be filled.
  const cv::Rect patch(75, 55, 10, 10);
  background(patch).copyTo(image(patch));
  cv::Mat image8, background8;
  AddNoise(image, 0.01, 4).convertTo(image8, CV_8UC3, 255.0);
  AddNoise(background, 0.01, 5).convertTo(background8, CV_8UC3, 255.0);

  const Silhouette silhouette = SilhouetteFromBackground(image8, background8);
  EXPECT_EQ(silhouette.source, EvidenceSource::kBackground);
  // The automatic (triangle) threshold lies below the disk's mean difference (d from 0.12
  // to 0.6 for this colour against a [0.2, 0.8] texture) ...
  EXPECT_LT(silhouette.threshold, cv::mean(silhouette.measure, truth)[0]);
  // ... and no speck of sensor noise (σ = 0.01 per image) survives the cleaning: nothing
  // farther than 2 px from the disk.
  cv::Mat near_disk;
  cv::dilate(truth, near_disk, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  EXPECT_EQ(cv::countNonZero(silhouette.mask & ~near_disk), 0);
  // The blurred edge (σ = 0.5 px) moves the boundary by at most a pixel: the IoU loses at
  // most perimeter × 1 px / area = 2π·35 / (π·35²) ≈ 5.7 %.
  EXPECT_GT(SilhouetteIoU(silhouette.mask, truth), 0.943);
  EXPECT_EQ(silhouette.mask.at<uint8_t>(60, 80), 255);  // the hole is filled

  // The same scene in gray gives the same silhouette to the same tolerance.
  cv::Mat gray_image, gray_background;
  cv::cvtColor(image8, gray_image, cv::COLOR_BGR2GRAY);
  cv::cvtColor(background8, gray_background, cv::COLOR_BGR2GRAY);
  EXPECT_GT(SilhouetteIoU(SilhouetteFromBackground(gray_image, gray_background).mask, truth), 0.943);

  // No object: the difference is noise below background_min_threshold → empty.
  EXPECT_TRUE(SilhouetteFromBackground(background8, background8).empty);
  EXPECT_THROW(BackgroundDifference(image8, gray_background), Error);
}

// An anti-aliased disk (pixel = its coverage, from an 8× supersampled drawing) of level 0.6
// on a dark background of 0.05: the exact mask is coverage > ½. The automatic threshold
// sits at the foot of the noise, where a pixel with a few per cent of coverage is object;
// moving the contour to half contrast (HalfContrastContour at ½) recovers the mask to
// within a few pixels, and the default silhouette is narrower than the unrefined one.
TEST(Silhouettes, HalfContrastContourRecoversTheHalfCoverageMask) {
  const int width = 120, height = 90, scale = 8;
  cv::Mat fine = cv::Mat::zeros(height * scale, width * scale, CV_32F);
  cv::circle(fine, cv::Point(60 * scale + 3, 45 * scale + 5), 30 * scale + 3, cv::Scalar(1), cv::FILLED);
  cv::Mat coverage;
  cv::resize(fine, coverage, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  const cv::Mat truth = coverage > 0.5f;
  cv::Mat image8, background8;
  cv::Mat(0.05f + 0.55f * coverage).convertTo(image8, CV_8U, 255.0);
  cv::Mat(cv::Mat::ones(height, width, CV_32F) * 0.05f).convertTo(background8, CV_8U, 255.0);

  SilhouetteOptions unrefined;
  unrefined.background_contour_fraction = 0;
  const Silhouette wide = SilhouetteFromBackground(image8, background8, unrefined);
  const cv::Mat half = HalfContrastContour(wide.measure, wide.mask, 0.5);
  const Silhouette refined = SilhouetteFromBackground(image8, background8);
  const int wrong_half = cv::countNonZero(half ^ truth);
  const int wrong_wide = cv::countNonZero(wide.mask ^ truth);
  const int wrong_default = cv::countNonZero(refined.mask ^ truth);
  std::printf("[ figures ] pixels differing from the half-coverage mask (perimeter ≈ 190 px): unrefined %d, "
              "half contrast %d, default (%.2f) %d\n",
              wrong_wide, wrong_half, SilhouetteOptions().background_contour_fraction, wrong_default);
  EXPECT_GT(wrong_wide, 100);  // about one ring of pixels too wide
  EXPECT_LT(wrong_half, 20);
  EXPECT_LT(wrong_default, wrong_wide / 2);
  EXPECT_EQ(cv::countNonZero(half & ~wide.mask), 0);  // only removes pixels
}

// The right half's texture moves one pixel per frame to the right; the left half is static.
TEST(Silhouettes, MotionEvidenceIsPositiveWhereTextureMovesAndZeroElsewhere) {
  const int width = 120, height = 80, half = width / 2;
  const cv::Mat still = Texture(width, height, 7);
  const cv::Mat moving = Texture(width + 8, height, 8);
  std::vector<cv::Mat> frames;
  for (int g = 0; g < 3; ++g) {
    cv::Mat frame = still.clone();
    moving(cv::Rect(4 - g, 0, half, height)).copyTo(frame(cv::Rect(half, 0, half, height)));
    frames.push_back(frame);
  }
  SilhouetteOptions options;
  const cv::Mat theta = MotionEvidence(frames, 1, options);
  // Left of the boundary by more than the smoothing support (3σ + 1 px): exactly nothing
  // changes, so θ = 0 (to float rounding).
  double left_max = 0;
  cv::minMaxLoc(theta(cv::Rect(0, 0, half - 5, height)), nullptr, &left_max);
  EXPECT_LT(left_max, 1e-6);
  const Silhouette silhouette = SilhouetteFromMotion(frames, 1, options);
  EXPECT_EQ(silhouette.source, EvidenceSource::kMotion);
  const cv::Mat right = silhouette.mask(cv::Rect(half, 0, half, height));
  const cv::Mat left = silhouette.mask(cv::Rect(0, 0, half, height));
  // Moving texture of features ~3 px has gradients almost everywhere; after the closing
  // the moving half is ≥ 95 % object, and the static half (but for the closing's reach of
  // 3 px at the boundary: 3 / 60 = 5 %) is background.
  EXPECT_GT(cv::countNonZero(right), 0.95 * right.total());
  EXPECT_LT(cv::countNonZero(left), 0.05 * left.total());

  // No motion at all: θ ≡ 0, the silhouette is empty.
  const std::vector<cv::Mat> static_frames = {still, still, still};
  double static_max = 0;
  cv::minMaxLoc(MotionEvidence(static_frames, 0, options), nullptr, &static_max);
  EXPECT_EQ(static_max, 0.0);
  EXPECT_TRUE(SilhouetteFromMotion(static_frames, 0, options).empty);
  EXPECT_THROW(MotionEvidence({still}, 0, options), Error);  // one frame has no ∂I/∂t
}

// Two legs (bars of 0.6 on a backdrop of 0.1), 5 px apart — the backdrop shows between
// them — and across the left leg a band 3 px high of a colour close to the backdrop's
// (difference 0.04, below the threshold of 0.06 and above half of it: a dark part of the
// object). The closing joins the leg across the dark band, and leaves the gap between the
// legs open: it adds only pixels that differ from the backdrop by half the threshold. A
// plain closing (background_close_floor 0) fills the gap, a web between the legs.
TEST(Silhouettes, BackgroundClosingJoinsDarkPartsButNotTheGapsBetweenLimbs) {
  const int width = 80, height = 80;
  cv::Mat image(height, width, CV_32F, cv::Scalar(0.1f));
  const cv::Rect left(20, 10, 12, 60), right(37, 10, 12, 60), band(20, 38, 12, 3);
  image(left).setTo(0.6f);
  image(right).setTo(0.6f);
  image(band).setTo(0.14f);
  cv::Mat image8, background8;
  image.convertTo(image8, CV_8U, 255.0);
  cv::Mat(cv::Mat::ones(height, width, CV_32F) * 0.1f).convertTo(background8, CV_8U, 255.0);

  SilhouetteOptions options;
  options.background_threshold = 0.06;
  options.background_shadow_test = false;
  const Silhouette silhouette = SilhouetteFromBackground(image8, background8, options);
  const cv::Mat gap = silhouette.mask(cv::Rect(33, 12, 3, 56));
  const cv::Mat joined = silhouette.mask(cv::Rect(23, 38, 6, 3));
  EXPECT_EQ(cv::countNonZero(gap), 0) << "the backdrop between the legs became object";
  EXPECT_EQ(cv::countNonZero(joined), joined.rows * joined.cols) << "the dark band was not joined";

  options.background_close_floor = 0;
  const Silhouette plain = SilhouetteFromBackground(image8, background8, options);
  EXPECT_GT(cv::countNonZero(plain.mask(cv::Rect(33, 12, 3, 56))), 100);  // the web a plain closing makes
  EXPECT_EQ(cv::countNonZero(plain.mask(cv::Rect(23, 38, 6, 3))), 18);

  // Against a background estimated from the video the subject's parts differ by little over
  // whole stretches (a shin against a pale floor), so there the closing stays plain: a band
  // that differs by less than half the threshold (0.02) is joined all the same.
  cv::Mat faint = image.clone();
  faint(band).setTo(0.12f);
  cv::Mat faint8;
  faint.convertTo(faint8, CV_8U, 255.0);
  EstimatedBackground estimated;
  estimated.image = cv::Mat(height, width, CV_32F, cv::Scalar(0.1f));
  estimated.known = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
  options.background_close_floor = 0.5;
  EXPECT_LT(cv::countNonZero(SilhouetteFromBackground(faint8, background8, options).mask(cv::Rect(23, 38, 6, 3))), 18);
  const Silhouette from_video = SilhouetteFromEstimatedBackground(faint8, estimated, options);
  EXPECT_EQ(cv::countNonZero(from_video.mask(cv::Rect(23, 38, 6, 3))), 18) << "the faint band was not joined";
}

// Two legs joined at the top and the bottom enclose a gap of the backdrop's colour: against
// a plain backdrop (a background of one colour) the gap is the backdrop seen through and
// stays open; a hole of the same size whose pixels are shaded just below the closing's
// floor (a dark part of the object) and a hole of a few pixels are filled. Behind a
// photographed background (not of one colour) every hole is filled, as before.
TEST(Silhouettes, APlainBackdropSeenThroughAGapTheObjectEnclosesStaysOpen) {
  const int width = 90, height = 90;
  cv::Mat image(height, width, CV_32F, cv::Scalar(0.1f));
  image(cv::Rect(15, 10, 60, 10)).setTo(0.6f);  // top bar
  image(cv::Rect(15, 70, 60, 10)).setTo(0.6f);  // bottom bar
  image(cv::Rect(15, 10, 10, 70)).setTo(0.6f);  // left leg
  image(cv::Rect(65, 10, 10, 70)).setTo(0.6f);  // right leg
  image(cv::Rect(45, 20, 10, 50)).setTo(0.6f);  // middle leg: two enclosed gaps
  const cv::Rect gap(27, 24, 16, 42), shaded(57, 24, 6, 42), speck(33, 44, 2, 2);
  // The right gap: the object's own dark part, shaded 0.005 … 0.025 above the backdrop (the
  // floor is half the threshold of 0.06: 0.03).
  for (int y = shaded.y; y < shaded.y + shaded.height; ++y)
    for (int x = shaded.x; x < shaded.x + shaded.width; ++x)
      image.at<float>(y, x) = 0.1f + 0.02f * static_cast<float>((x + y) % 3) / 2.0f + 0.005f;
  cv::Mat image8, backdrop8;
  image.convertTo(image8, CV_8U, 255.0);
  cv::Mat(height, width, CV_32F, cv::Scalar(0.1f)).convertTo(backdrop8, CV_8U, 255.0);

  SilhouetteOptions options;
  options.background_threshold = 0.06;
  options.background_shadow_test = false;
  const Silhouette plain = SilhouetteFromBackground(image8, backdrop8, options);
  EXPECT_EQ(cv::countNonZero(plain.mask(gap)), 0) << "the backdrop seen through the gap was filled";
  EXPECT_EQ(cv::countNonZero(plain.mask(shaded)), shaded.area()) << "the object's dark part was opened";

  // A speck of a few pixels is noise, filled like any small region.
  cv::Mat specked = image.clone();
  specked(gap).setTo(0.6f);
  specked(speck).setTo(0.1f);
  cv::Mat specked8;
  specked.convertTo(specked8, CV_8U, 255.0);
  EXPECT_EQ(cv::countNonZero(SilhouetteFromBackground(specked8, backdrop8, options).mask(speck)), speck.area());

  // Behind a photographed room (a background not of one colour) a hole of what lies
  // behind may be the object matching it: filled as before.
  cv::Mat room = backdrop8.clone();
  room(cv::Rect(0, 85, width, 5)).setTo(40);
  cv::Mat in_room = image8.clone();
  room(cv::Rect(0, 85, width, 5)).copyTo(in_room(cv::Rect(0, 85, width, 5)));
  EXPECT_EQ(cv::countNonZero(SilhouetteFromBackground(in_room, room, options).mask(gap)), gap.area());
}

TEST(Silhouettes, OptionsAreChecked) {
  SilhouetteOptions options;
  EXPECT_NO_THROW(options.Check());
  options.motion_lambda = 0;
  try {
    options.Check();
    FAIL() << "motion_lambda = 0 accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("motion_lambda"), std::string::npos);
  }
  EXPECT_EQ(ParseEvidenceSource("background"), EvidenceSource::kBackground);
  EXPECT_THROW(ParseEvidenceSource("silhouette"), Error);
}

// ../shared/data/blob has masks, a background and motion: kAuto takes the masks, as given.
TEST(Silhouettes, AutoSourceTakesGivenMasksFirst) {
  const Dataset blob(SUBFLOW_SHARED_DIR "/data/blob");
  const std::vector<Silhouette> silhouettes = ComputeSilhouettes(blob, 3);
  ASSERT_EQ(static_cast<int>(silhouettes.size()), blob.camera_count());
  for (int c = 0; c < blob.camera_count(); ++c) {
    EXPECT_EQ(silhouettes[c].source, EvidenceSource::kMask);
    EXPECT_EQ(cv::countNonZero(silhouettes[c].mask != blob.Mask(c, 3)), 0);
  }
}

// A tiny dataset on disk: 3 cameras, 3 frames, no masks, no background.
class StaticDataset : public ::testing::Test {
 protected:
  void SetUp() override {
    std::vector<Camera> cameras;
    for (int c = 0; c < 3; ++c) {
      const double angle = 2.0 * M_PI * c / 3.0;
      const Eigen::Vector3d centre(0.6 * std::cos(angle), 0.6 * std::sin(angle), 0.0);
      const Eigen::Vector3d z = -centre.normalized(), y(0, 0, -1);
      Eigen::Matrix3d R;
      R.row(0) = y.cross(z);
      R.row(1) = y;
      R.row(2) = z;
      Eigen::Matrix3d K;
      K << 100, 0, 39.5, 0, 100, 29.5, 0, 0, 1;
      cameras.emplace_back("cam" + std::to_string(c), 80, 60, K, R, -R * centre);
    }
    DatasetInfo info;
    info.frame_count = 3;
    info.bounds = Bounds{Eigen::Vector3d::Constant(-0.1), Eigen::Vector3d::Constant(0.1)};
    DatasetWriter writer(directory_, cameras, info, /*overwrite=*/true);
    for (int c = 0; c < 3; ++c) {
      cv::Mat image;
      Texture(80, 60, 20 + c).convertTo(image, CV_8U, 255.0);
      for (int f = 0; f < 3; ++f) writer.WriteImage(c, f, image);  // nothing moves
    }
  }
  const test::TemporaryDirectory scratch_{"silhouettes_test"};
  const std::string directory_ = scratch_.string();
};

TEST_F(StaticDataset, NoMasksNoBackgroundNoMotionIsAnErrorThatSaysSo) {
  const Dataset dataset(directory_);
  try {
    ComputeSilhouettes(dataset, 1);
    FAIL() << "a static dataset without masks or background gave silhouettes";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("no masks, no background, and no motion: cannot find the object"),
              std::string::npos)
        << error.what();
  }
  SilhouetteOptions forced;
  forced.source = EvidenceSource::kMask;
  EXPECT_THROW(ComputeSilhouettes(dataset, 1, forced), Error);  // no masks to force
  forced.source = EvidenceSource::kBackground;
  EXPECT_THROW(ComputeSilhouettes(dataset, 1, forced), Error);  // no background either
  EXPECT_THROW(ComputeSilhouettes(dataset, 3), Error);          // frame out of range
}

}  // namespace
}  // namespace subflow::vision
