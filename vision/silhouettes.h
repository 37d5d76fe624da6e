// Object evidence per camera and frame (method §4.1): a silhouette of the object in each
// image, from the best source the dataset offers, in this order:
//
//  1. kMask        given masks (masks/<camera>/<frame>.png): evidence = mask / 255.
//  2. kBackground  the difference to the background image: per-pixel distance
//                  d(p) = sqrt(Σ_c (I_c(p) − B_c(p))² / C) over the C colour channels of
//                  intensities in [0, 1] (gray: |I − B|), slightly Gaussian-blurred,
//                  thresholded (automatic: triangle or Otsu on d; or a fixed value), then
//                  cleaned (2D opening, closing, small regions removed, holes filled),
//                  and its contour moved to where the object covers half of a pixel.
//                  Without masks and background image, the background is estimated from
//                  the video itself (EstimateBackground), when it has enough frames.
//  3. kMotion      motion evidence, method eq. 23, per pixel and frame g:
//                      θ_g(p) = |∂I/∂t(p)| / (λ + ‖∇I(p)‖²)
//                  with I the Gaussian-smoothed gray image (σ = motion_sigma), ∇I central
//                  differences in space (intensity / pixel), ∂I/∂t central differences in
//                  time over frames g−1, g+1 (one-sided at the first and last frame;
//                  intensity / frame). A point that does not move between one pair of
//                  frames gives no evidence there, so θ is accumulated (maximum) over the
//                  window g ∈ [f − w, f + w]; then thresholded (automatic: Otsu or
//                  triangle; or a fixed value) and cleaned as above (no opening): the
//                  thresholded θ marks moving texture and contours, the cleaning turns
//                  that into a filled silhouette.
//
// Every source ends as a silhouette (evidence 0 / 1), which voxel carving integrates over
// each voxel's footprint (vision/voxel_carving.h). For motion this departs slightly from
// the paper, which integrates θ itself and thresholds per voxel: thresholding θ in the
// image first lets one automatic threshold per image serve all voxels and lets the 2D
// cleaning fill the flat, texture-less parts of the object, where θ is 0.
//
// Conventions: images are in RAW image coordinates (as stored, lens distortion not
// removed); pixel (0, 0) is the centre of the top-left pixel (DATASET.md). Whoever
// projects 3D points onto these silhouettes must therefore use Camera::Project (with
// distortion), not ProjectUndistorted — voxel carving does.
//
// Intensities are gray CV_32F in [0, 1] (Dataset::Gray); thresholds of the background
// difference are in those units; θ is in (intensity / frame) / (intensity / pixel)².
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace subflow::vision {

class Camera;
class Dataset;

enum class EvidenceSource {
  kAuto,        // options only: masks if the dataset has them, else background, else motion
  kMask,
  kBackground,
  kMotion,
  // Photo-consistency of a still image set (vision/still_evidence.h): computed by shape
  // initialization (solver/shape/shape_init.h) when nothing moves, or when asked for.
  kStill,
};
// "auto", "mask", "background", "motion", "still" (as written in report.json and read by the CLI).
std::string ToString(EvidenceSource source);
// Inverse of ToString; throws subflow::Error naming `field` on anything else.
EvidenceSource ParseEvidenceSource(const std::string& text, const std::string& field = "source");

// Automatic thresholds of a measure image (see OtsuThreshold, TriangleThreshold).
enum class ThresholdMethod {
  kOtsu,      // two classes of maximal between-class variance: for two well-separated modes
  kTriangle,  // the foot of the dominant (background) peak: for a peak plus a long tail
};
// "otsu", "triangle".
std::string ToString(ThresholdMethod method);

struct SilhouetteOptions {
  // Which evidence to use. kAuto takes, per camera, the first of mask / background /
  // motion that the dataset offers; a forced source that the dataset lacks is an error.
  EvidenceSource source = EvidenceSource::kAuto;

  // --- background difference ---
  // σ (pixels) of the Gaussian blur of the difference image: suppresses pixel noise, but
  // widens the silhouette by up to a pixel at the low automatic threshold. 0 = no blur.
  double background_blur_sigma = 0.5;
  // Threshold on the blurred difference (intensity units, [0, 1]); < 0 = automatic
  // (background_method on the difference image, never below background_min_threshold).
  double background_threshold = -1.0;
  // Automatic method for the background difference. Triangle: the difference image is a
  // peak of background noise plus a long tail of object pixels whose shaded parts come
  // close to the background; Otsu splits the object's bright and dark parts instead.
  ThresholdMethod background_method = ThresholdMethod::kTriangle;
  // Radius (pixels) of a 2D opening of the thresholded difference, before the closing:
  // removes specks of sensor noise above the threshold (which the closing would otherwise
  // glue onto the object as spikes). Not applied to motion evidence, whose thresholded θ
  // is made of thin texture edges. 0 = none.
  int background_open_radius = 1;
  // Lower bound of the automatic threshold: differences below this are always noise
  // (0.02 ≈ 5 gray levels of an 8-bit image). Keeps the automatic threshold from
  // splitting pure noise when the object is absent.
  double background_min_threshold = 0.02;
  // Contour refinement (HalfContrastContour): a pixel near the silhouette's contour stays
  // object only when its difference reaches this fraction of the object's mean difference
  // just inside. The automatic threshold sits at the foot of the noise, where a pixel with
  // a few per cent of object already counts, so without it the silhouette is ~½–1 pixel
  // too wide (IoU vs the masks 0.97–0.98, false positives 2 % of the object's pixels on
  // the synth scenes and ../shared/data/blob), and so is the strict hull carved from it.
  // ½ is exact for an object of constant colour; on shaded objects the contour is darker
  // than the interior mean (light falls off towards the limb), and ½ then cuts ~1 % of the
  // object; 0.35 balances the missed and the extra pixels there (each 0.3–0.9 %, IoU
  // 0.98–0.99 on the same data). 0 = off.
  double background_contour_fraction = 0.35;
  // Shadow-robust comparison (vision/silhouettes_background.h): a pixel that one gain in
  // [shadow_min_gain, shadow_max_gain] of the background explains, together with the
  // texture of a (2·shadow_window_radius + 1)² window around it, is background (a soft
  // shadow, a change of exposure). false = the plain colour difference d.
  bool background_shadow_test = true;
  // Darkest shadow, as a gain on linear radiance: a shadow keeps at least this fraction of
  // the light (ambient and fill light reach into it). Lower = deeper shadows taken for
  // background, and dark objects over the background's texture with them.
  double shadow_min_gain = 0.2;
  // Brightest "shadow": > 1 admits an exposure or lighting change that brightens.
  double shadow_max_gain = 1.1;
  // Half-size (pixels) of the window whose texture one gain must explain: larger windows
  // hold more texture (a surer test), smaller ones follow a penumbra's gradient better.
  int shadow_window_radius = 2;
  // Per-camera threshold: median + this many robust σ (1.4826 MAD) of the difference
  // over the pixels outside the projected working volume (never below
  // background_min_threshold). Used when background_threshold < 0 and at least
  // min_background_fraction of the image is outside; else background_method.
  double background_noise_factor = 6.0;
  // Margin (pixels, as a fraction of the image's diagonal) around the working volume's
  // projection within which a pixel is not taken as surely background.
  double working_volume_margin = 0.02;
  // Fewest surely-background pixels (fraction of the image) for a per-camera threshold.
  double min_background_fraction = 0.02;

  // --- motion evidence (eq. 23) ---
  // σ (pixels) of the spatial Gaussian smoothing before the derivatives.
  double motion_sigma = 1.0;
  // λ of eq. 23, in (intensity / pixel)²: θ peaks where ‖∇I‖ ≈ √λ; it keeps θ defined on
  // flat regions. 1e-3 ↔ gradients of ~0.03 per pixel (8 gray levels per pixel).
  double motion_lambda = 1e-3;
  // Half-width w of the temporal window: θ is accumulated over frames f−w .. f+w
  // (clipped to the sequence). Larger windows fill in points that pause, but the
  // silhouette becomes the union of the object's positions over the window, and the hull
  // carved from it grows: on the blob, rigid and head synth scenes and ../shared/data/blob
  // (10-camera ring, motion evidence only) the fitted surface's accuracy P90 / completeness
  // were 9.2 / 8.1 / 4.3 / 8.0 mm and 34 / 51 / 83 / 28 % with w = 0, against
  // 11.3 / 10.0 / 4.8 / 9.7 mm and 20 / 51 / 79 / 24 % with w = 2. A frame in which nothing
  // moves gets no evidence; shape initialization then takes the nearest frame's hull.
  int motion_window = 0;
  // Threshold on the accumulated θ; < 0 = automatic (motion_method, never below
  // motion_min_threshold).
  double motion_threshold = -1.0;
  // Automatic method for θ. Otsu: θ of moving texture and contours forms a mode of its
  // own above the static background's θ ≈ 0 (on ../shared/data/blob the cleaned motion
  // silhouettes match the masks with mean IoU 0.93 with Otsu, 0.91 with triangle).
  ThresholdMethod motion_method = ThresholdMethod::kOtsu;
  // Lower bound of the automatic motion threshold (θ units). A static scene gives θ = 0
  // up to image noise; θ below this is no motion.
  double motion_min_threshold = 0.5;

  // --- background estimated from the video (no masks, no background image) ---
  // With source kAuto, a camera without masks and without background image gets a
  // background estimated from its own video (EstimateBackground) when the dataset has at
  // least background_estimate_min_frames frames, and its silhouettes come from the
  // difference to it (as kBackground, contour correction included) instead of raw motion
  // evidence. false = motion evidence as before.
  bool estimate_background = true;
  int background_estimate_min_frames = 3;
  // A pixel is "free" at a frame when it lies farther than this many pixels from that
  // frame's motion silhouette (the motion silhouette misses the blurred contour and the
  // object's flat parts near it). A wider margin leaves more pixels never free (unknown,
  // taken as object: fatter hulls); a narrower one lets the object into the median. On
  // the blob, rigid and head synth scenes and ../shared/data/blob without masks and
  // background, accuracy P90 / completeness of the fitted surface were
  // 9.7 / 4.7 / 4.1 / 4.9 mm, 82 / 79 / 84 / 82 % with 1;
  // 8.3 / 4.4 / 3.4 / 5.0 mm, 79 / 82 / 89 / 83 % with 2;
  // 7.6 / 5.3 / 3.6 / 6.2 mm, 69 / 78 / 87 / 75 % with 3; blob 10.8 mm, 30 % with 6.
  int background_estimate_margin = 2;

  // --- cleaning of thresholded background / motion evidence (not of given masks) ---
  // Radius (pixels) of the 2D morphological closing of the thresholded image (joins
  // moving texture and contour fragments into one region, closes bites of weak evidence
  // at the contour). A plain closing also fills real gaps narrower than 2r + 1 pixels
  // (between legs); background_close_floor keeps those open. 0 = none.
  int close_radius = 5;
  // The closing of background-difference silhouettes adds only pixels whose difference
  // reaches this fraction of the threshold. What the closing is for — parts of the object
  // that differ from the background a little, below the threshold, between parts that
  // differ more — stays joined; the background seen between two legs, or between an arm
  // and the body, differs not at all and stays open (a plain closing filled such gaps
  // narrower than 2r + 1 pixels: webs the hull then kept; docs/shape.md, "Gaps between
  // limbs"). For a background image and a plain backdrop; not for a background estimated
  // from the video (whose differences on the subject are weak: SilhouetteFromEstimatedBackground),
  // nor for motion evidence, whose closing fills the flat, untextured inside of the object,
  // where θ is 0. 0 = a plain closing.
  double background_close_floor = 0.5;
  // A background image's silhouettes are the object's outlines (Silhouette::outline): the
  // hull is carved as from masks, and the later stages take them as masks, recomputed per
  // frame (ImageSequence, StageState::background_outlines; docs/shape.md, "Gaps between
  // limbs"). false = the projected hull bounds them, as before 2026-12-07.
  bool background_outlines = true;
  // Fill holes of the silhouette (background regions not connected to the image border).
  // Right for objects without through-holes; turn off for a torus seen through its hole.
  // Against a plain backdrop (a background of one colour) the parts of a hole that look
  // like the backdrop stay open all the same (ThresholdAndClean, open_seen_through_holes).
  bool fill_holes = true;
  // Connected object regions smaller than this many pixels are removed (noise). 0 = keep all.
  int min_region_pixels = 20;

  // A silhouette with fewer object pixels than this is "empty" (see Silhouette::empty).
  int min_object_pixels = 1;

  // Throws subflow::Error naming the field when an option is out of range.
  void Check() const;
};

// The object evidence of one camera at one frame.
struct Silhouette {
  EvidenceSource source = EvidenceSource::kMask;  // the source actually used
  // CV_32FC1, the camera's size, values in [0, 1]: the evidence voxel carving integrates
  // over voxel footprints (here the cleaned binary silhouette as 0 / 1).
  cv::Mat evidence;
  // CV_8UC1 0 / 255: the silhouette (evidence ≥ 0.5).
  cv::Mat mask;
  // CV_32FC1: the raw measure before thresholding (mask / 255, background distance d, or
  // accumulated θ), for figures and debugging.
  cv::Mat measure;
  // Threshold applied to `measure` (0.5 for masks).
  double threshold = 0.5;
  int object_pixels = 0;  // non-zero pixels of `mask`
  bool empty = true;      // object_pixels < options.min_object_pixels
  // A measured silhouette that is the object's own outline, as a mask is: the difference to
  // a plain backdrop (solver/shape/shape_init.cpp, BackdropSilhouettes), where whatever
  // differs from the backdrop is the object, or to a background image
  // (SilhouetteOptions::background_outlines). Carved without the hull's cleaning, and the
  // refinement pulls the surface's rim onto it, as for masks (docs/shape.md, "Gaps between
  // limbs, and a backdrop's silhouettes as outlines"). Masks are outlines whatever this says.
  bool outline = false;
};

// Otsu's threshold of a CV_32FC1 image: the value t maximizing the between-class
// variance of {v ≤ t} and {v > t}, from a 256-bin histogram over [min, the 99.9th
// percentile] (values above fall into the last bin). Returns the value itself when the
// image is constant. Non-finite values are ignored.
double OtsuThreshold(const cv::Mat& values);
// The triangle threshold (Zack et al. 1977) of the same histogram: the bin farthest below
// the chord from the histogram's peak to the end of its tail on the high side, i.e. the
// foot of the peak. Suits a dominant background peak with a long tail of object values.
double TriangleThreshold(const cv::Mat& values);

// Silhouette from a given mask (CV_8UC1, non-zero = object). No cleaning.
Silhouette SilhouetteFromMask(const cv::Mat& mask, const SilhouetteOptions& options = {});

// CV_32F in [0, 1] with the same channels (CV_8U, CV_16U or CV_32F in; 4 channels lose alpha).
cv::Mat ToUnitFloat(const cv::Mat& image);

// Per-pixel distance d of an image to the background (same size and type; CV_8U,
// CV_16U or CV_32F in [0, 1]; 1, 3 or 4 channels, alpha ignored), CV_32FC1 in [0, 1],
// not yet blurred.
cv::Mat BackgroundDifference(const cv::Mat& image, const cv::Mat& background);
// Silhouette from the background difference (see the file comment), with the
// shadow-robust comparison and the per-camera threshold of vision/silhouettes_background.h.
// `surely_background`: CV_8UC1, 255 at pixels that cannot show the object
// (OutsideWorkingVolume), for the per-camera threshold; empty = none known.
Silhouette SilhouetteFromBackground(const cv::Mat& image, const cv::Mat& background,
                                    const SilhouetteOptions& options = {},
                                    const cv::Mat& surely_background = cv::Mat());

// The contour of a silhouette moved to where a straight edge is half covered: pixels of
// `mask` within 2 pixels of its contour are removed when measure(p) < fraction × the mean
// measure of the silhouette's interior (pixels ≥ 3 from the contour) within 5 pixels. On
// a blurred measure of a straight edge between constant levels, the fraction 0.5 lands on
// the edge itself. Pixels with no interior near them (thin parts) are kept.
cv::Mat HalfContrastContour(const cv::Mat& measure, const cv::Mat& mask, double fraction);

// Accumulated motion evidence θ (eq. 23) at frame `index` of a contiguous sequence of
// gray images (CV_32FC1, [0, 1], all the same size; at least 2 frames): the maximum of
// θ_g over g ∈ [index − motion_window, index + motion_window] ∩ [0, size − 1].
cv::Mat MotionEvidence(const std::vector<cv::Mat>& gray_frames, int index,
                       const SilhouetteOptions& options = {});
// Silhouette from MotionEvidence (thresholded and cleaned).
Silhouette SilhouetteFromMotion(const std::vector<cv::Mat>& gray_frames, int index,
                                const SilhouetteOptions& options = {});

// A background image estimated from one camera's video: per pixel and channel, the
// temporal median over the frames where the pixel is free, i.e. outside that frame's
// motion silhouette (SilhouetteFromMotion) dilated by background_estimate_margin.
// A pixel free in no frame is unknown (the object covers it, or moves there, in every
// frame); the silhouettes take it as object (SilhouetteFromEstimatedBackground).
struct EstimatedBackground {
  cv::Mat image;  // CV_32FC1 or CV_32FC3 in [0, 1] (the frames' channels, alpha dropped); empty = none
  cv::Mat known;  // CV_8UC1, 255 where the pixel was free in at least one frame
  // CV_32FC1: per pixel, the median absolute deviation of the gray free samples from their
  // median (0 where unknown): sensor and compression noise on the static scene, more
  // where something in it sways — a person standing (almost) still, whom the median
  // keeps (vision/standing_evidence.h).
  cv::Mat instability;
  int frames = 0;                 // frames of the video the estimate was made from
  double known_fraction = 0;      // fraction of the pixels that are known
  double mean_free_frames = 0;    // mean number of frames a known pixel was free in
  bool valid() const { return !image.empty(); }
};
// `images`: the camera's frames (CV_8U, CV_16U or CV_32F in [0, 1]; 1, 3 or 4 channels);
// `gray_frames`: the same frames as gray CV_32FC1 (for the motion evidence). At least
// 2 frames of one size; throws subflow::Error otherwise. No estimate (valid() false)
// when no frame has any motion evidence: nothing tells the object from the background.
EstimatedBackground EstimateBackground(const std::vector<cv::Mat>& images,
                                       const std::vector<cv::Mat>& gray_frames,
                                       const SilhouetteOptions& options = {});
// Silhouette from the difference of `image` to an estimated background: the plain
// difference (no shadow test) with the histogram threshold, the difference of unknown
// pixels set to 1 (object). Source kBackground.
Silhouette SilhouetteFromEstimatedBackground(const cv::Mat& image, const EstimatedBackground& background,
                                             const SilhouetteOptions& options = {});

// Thresholds a CV_32FC1 measure (v > threshold → object) and cleans the result: opening
// of radius open_radius, closing of radius options.close_radius (disks), regions under
// options.min_region_pixels removed, holes filled (options.fill_holes); fills every
// field of the returned Silhouette except `source`.
// With close_floor > 0, the closing adds only pixels whose measure is ≥ close_floor, and
// with open_seen_through_holes the holes' regions that look like the background seen through
// a gap the object encloses stay open (FillHoles in silhouettes.cpp): for a plain backdrop,
// where such a region is the backdrop (docs/shape.md, "Holes the backdrop is seen through").
Silhouette ThresholdAndClean(const cv::Mat& measure, double threshold,
                             const SilhouetteOptions& options, int open_radius = 0, double close_floor = 0,
                             bool open_seen_through_holes = false);

// The evidence camera `camera` of `dataset` takes for EvidenceSource::kAuto: masks if the
// dataset has them, else the background image if background/<camera>.png exists, else
// motion. The one rule for shape initialization and the refinement's silhouettes.
EvidenceSource AutomaticSource(const Dataset& dataset, int camera);

// Whether `silhouettes` say nothing about where the object is: every silhouette is empty
// (the object has left the working volume in that frame), or every camera uses motion
// evidence and fewer than `min_cameras` of them have a non-empty silhouette (a frame of a
// mask-less dataset in which nothing moves within the motion window).
bool LacksEvidence(const std::vector<Silhouette>& silhouettes, int min_cameras = 1);

// The silhouette of camera `camera` at `frame` from its background image (which must
// exist), as ComputeFrameEvidence makes it (`working` likewise).
Silhouette BackgroundImageSilhouette(const Dataset& dataset, int camera, int frame, const SilhouetteOptions& options,
                                     const std::vector<Camera>* working = nullptr);

// Silhouettes of every camera of `dataset` at `frame` (index = camera index), cameras in
// parallel. Source per camera: options.source, or for kAuto masks if has_masks(), else
// background if background/<camera>.png exists, else motion. Motion reads the gray
// frames f − w − 1 .. f + w + 1 (clipped). A frame without evidence (LacksEvidence) is
// returned as it is. Throws subflow::Error when a forced source is missing from the dataset.
// `estimated`: per camera, a background estimated from the video (EstimateBackgrounds),
// used instead of motion evidence by a camera whose source (kAuto) would be motion.
// `working`: per camera, the working camera (vision/working_scale.h) whose size the
// images are resized to before anything is computed; null = the stored size.
std::vector<Silhouette> ComputeFrameEvidence(const Dataset& dataset, int frame,
                                             const SilhouetteOptions& options = {},
                                             const std::vector<EstimatedBackground>* estimated = nullptr,
                                             const std::vector<Camera>* working = nullptr);
// Backgrounds estimated from the video for every camera whose kAuto source would be
// motion (no masks, no background/<camera>.png), from all frames of the dataset (at
// most 64, evenly spaced); empty entries for the other cameras. Empty when
// options.estimate_background is off, options.source is not kAuto, or the dataset has
// fewer than background_estimate_min_frames frames. `working` as for ComputeFrameEvidence.
std::vector<EstimatedBackground> EstimateBackgrounds(const Dataset& dataset, const SilhouetteOptions& options = {},
                                                     const std::vector<Camera>* working = nullptr);
// ComputeFrameEvidence, and when every motion silhouette is empty the error
// "<dataset>: frame N: no masks, no background, and no motion: cannot find the object".
std::vector<Silhouette> ComputeSilhouettes(const Dataset& dataset, int frame,
                                           const SilhouetteOptions& options = {});

}  // namespace subflow::vision
