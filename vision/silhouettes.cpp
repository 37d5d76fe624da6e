#include "vision/silhouettes.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "vision/silhouettes_background.h"

namespace subflow::vision {
namespace {

void CheckRange(bool ok, const char* field, const std::string& expected, double value) {
  if (!ok)
    ThrowError("SilhouetteOptions", field,
               "expected " + expected + ", got " + std::to_string(value));
}

void RemoveSmallRegions(cv::Mat* mask, int min_pixels) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(*mask, labels, stats, centroids, 8, CV_32S);
  std::vector<uint8_t> keep(count, 0);
  for (int label = 1; label < count; ++label)
    keep[label] = stats.at<int>(label, cv::CC_STAT_AREA) >= min_pixels;
  for (int y = 0; y < mask->rows; ++y) {
    const int* label_row = labels.ptr<int>(y);
    uint8_t* row = mask->ptr<uint8_t>(y);
    for (int x = 0; x < mask->cols; ++x)
      if (row[x] && !keep[label_row[x]]) row[x] = 0;
  }
}

// The q-quantile of `values`' pixels under `where` (CV_8UC1), or -1 when there are none.
double QuantileUnder(const cv::Mat& values, const cv::Mat& where, double q) {
  std::vector<float> selected;
  for (int y = 0; y < values.rows; ++y) {
    const float* value = values.ptr<float>(y);
    const uint8_t* in = where.ptr<uint8_t>(y);
    for (int x = 0; x < values.cols; ++x)
      if (in[x]) selected.push_back(value[x]);
  }
  if (selected.empty()) return -1.0;
  const auto k = selected.begin() + static_cast<long>(q * static_cast<double>(selected.size() - 1));
  std::nth_element(selected.begin(), k, selected.end());
  return *k;
}

// Whether every pixel of `image` (CV_32F, any channels) equals its first: a plain backdrop.
// A photographed background differs within its first pixels, so the scan stops there.
bool OneColour(const cv::Mat& image) {
  const int channels = image.channels();
  const float* first = image.ptr<float>(0);
  for (int y = 0; y < image.rows; ++y) {
    const float* row = image.ptr<float>(y);
    for (int i = 0; i < image.cols * channels; ++i)
      if (row[i] != first[i % channels]) return false;
  }
  return true;
}

// Fills the holes of `mask` (background not reachable from the image border). With a
// floor (> 0), a hole's region that is the background seen through a gap the object's
// projection encloses (between crossed legs, an arm on the hip) stays open: a connected
// region of at least `min_pixels` pixels whose measure is below the floor and, at its
// median, no higher than the background around the object at its 75th percentile (or a
// quarter of the floor). A dark part of the object whose measure stays under the floor (an
// eye socket against a dark backdrop) has shading the backdrop does not have and is filled,
// as is every region of fewer pixels (noise).
void FillHoles(cv::Mat* mask, const cv::Mat& measure, double floor, int min_pixels) {
  cv::Mat padded;
  cv::copyMakeBorder(*mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(128));
  const cv::Mat reached = padded(cv::Rect(1, 1, mask->cols, mask->rows));
  const cv::Mat holes = reached == 0;
  mask->setTo(255, holes);
  if (floor <= 0 || measure.empty() || cv::countNonZero(holes) == 0) return;
  // A region's median at most the background's own level around the object, or a quarter
  // of the floor where that is smaller (a noise-free render's 0, which the smoothing of the
  // measure raises a little inside a narrow gap).
  const double around = QuantileUnder(measure, reached == 128, 0.75);
  if (around < 0) return;
  const double open_level = std::max(around, 0.25 * floor);
  cv::Mat candidates = holes & (measure < floor);
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(candidates, labels, stats, centroids, 8, CV_32S);
  // Every large enough region's values in one pass over the image (row-major, as a scan of
  // the region alone would take them), then its median.
  std::vector<std::vector<float>> values(count);
  const auto large = [&](int label) {
    return label > 0 && stats.at<int>(label, cv::CC_STAT_AREA) >= std::max(1, min_pixels);
  };
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x)
      if (const int label = labels.at<int>(y, x); large(label)) values[label].push_back(measure.at<float>(y, x));
  std::vector<uint8_t> open(count, 0);
  for (int label = 1; label < count; ++label) {
    if (values[label].empty()) continue;
    std::vector<float>& v = values[label];
    const auto median = v.begin() + static_cast<long>(0.5 * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), median, v.end());
    open[label] = *median <= open_level;
  }
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x)
      if (open[labels.at<int>(y, x)]) mask->at<uint8_t>(y, x) = 0;
}

cv::Mat Smooth(const cv::Mat& gray, double sigma) {
  if (sigma <= 0) return gray;
  cv::Mat smoothed;
  cv::GaussianBlur(gray, smoothed, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
  return smoothed;
}

double AutomaticThreshold(const cv::Mat& measure, double fixed, ThresholdMethod method, double minimum) {
  if (fixed >= 0) return fixed;
  return std::max(method == ThresholdMethod::kOtsu ? OtsuThreshold(measure) : TriangleThreshold(measure), minimum);
}

}  // namespace

cv::Mat ToUnitFloat(const cv::Mat& image) {
  double scale = 1.0;
  if (image.depth() == CV_8U) scale = 1.0 / 255.0;
  else if (image.depth() == CV_16U) scale = 1.0 / 65535.0;
  else if (image.depth() != CV_32F)
    ThrowError("", "image", "expected CV_8U, CV_16U or CV_32F pixels");
  cv::Mat result;
  image.convertTo(result, CV_32F, scale);
  if (result.channels() == 4) cv::cvtColor(result, result, cv::COLOR_BGRA2BGR);
  return result;
}

std::string ToString(EvidenceSource source) {
  switch (source) {
    case EvidenceSource::kAuto: return "auto";
    case EvidenceSource::kMask: return "mask";
    case EvidenceSource::kBackground: return "background";
    case EvidenceSource::kMotion: return "motion";
    case EvidenceSource::kStill: return "still";
  }
  return "?";
}

std::string ToString(ThresholdMethod method) {
  return method == ThresholdMethod::kOtsu ? "otsu" : "triangle";
}

EvidenceSource ParseEvidenceSource(const std::string& text, const std::string& field) {
  for (EvidenceSource source : {EvidenceSource::kAuto, EvidenceSource::kMask, EvidenceSource::kBackground,
                                EvidenceSource::kMotion, EvidenceSource::kStill})
    if (text == ToString(source)) return source;
  ThrowError("", field, "expected auto, mask, background, motion or still, got \"" + text + "\"");
}

void SilhouetteOptions::Check() const {
  CheckRange(background_blur_sigma >= 0 && background_blur_sigma <= 50, "background_blur_sigma",
             "a value in [0, 50] pixels", background_blur_sigma);
  CheckRange(background_threshold < 1, "background_threshold",
             "a value below 1 (negative = automatic)", background_threshold);
  CheckRange(background_min_threshold >= 0 && background_min_threshold < 1,
             "background_min_threshold", "a value in [0, 1)", background_min_threshold);
  CheckRange(background_contour_fraction >= 0 && background_contour_fraction < 1,
             "background_contour_fraction", "a value in [0, 1) (0 = off)", background_contour_fraction);
  CheckRange(shadow_min_gain > 0 && shadow_min_gain <= 1, "shadow_min_gain", "a gain in (0, 1]",
             shadow_min_gain);
  CheckRange(shadow_max_gain >= 1 && shadow_max_gain <= 10, "shadow_max_gain", "a gain in [1, 10]",
             shadow_max_gain);
  CheckRange(shadow_window_radius >= 1 && shadow_window_radius <= 20, "shadow_window_radius",
             "an integer in [1, 20] pixels", shadow_window_radius);
  CheckRange(background_noise_factor > 0 && background_noise_factor <= 100, "background_noise_factor",
             "a value in (0, 100]", background_noise_factor);
  CheckRange(working_volume_margin >= 0 && working_volume_margin <= 1, "working_volume_margin",
             "a fraction of the image diagonal in [0, 1]", working_volume_margin);
  CheckRange(min_background_fraction > 0 && min_background_fraction <= 1, "min_background_fraction",
             "a fraction in (0, 1]", min_background_fraction);
  CheckRange(motion_sigma >= 0 && motion_sigma <= 50, "motion_sigma", "a value in [0, 50] pixels",
             motion_sigma);
  CheckRange(motion_lambda > 0 && std::isfinite(motion_lambda), "motion_lambda",
             "a positive value", motion_lambda);
  CheckRange(motion_window >= 0 && motion_window <= 100, "motion_window",
             "an integer in [0, 100]", motion_window);
  CheckRange(std::isfinite(motion_threshold), "motion_threshold",
             "a finite value (negative = automatic)", motion_threshold);
  CheckRange(motion_min_threshold >= 0 && std::isfinite(motion_min_threshold),
             "motion_min_threshold", "a non-negative value", motion_min_threshold);
  CheckRange(background_estimate_min_frames >= 2 && background_estimate_min_frames <= 1000,
             "background_estimate_min_frames", "an integer in [2, 1000]", background_estimate_min_frames);
  CheckRange(background_estimate_margin >= 0 && background_estimate_margin <= 100, "background_estimate_margin",
             "an integer in [0, 100] pixels", background_estimate_margin);
  CheckRange(background_open_radius >= 0 && background_open_radius <= 100, "background_open_radius",
             "an integer in [0, 100] pixels", background_open_radius);
  CheckRange(close_radius >= 0 && close_radius <= 100, "close_radius",
             "an integer in [0, 100] pixels", close_radius);
  CheckRange(background_close_floor >= 0 && background_close_floor <= 1, "background_close_floor",
             "a fraction in [0, 1]", background_close_floor);
  CheckRange(min_region_pixels >= 0, "min_region_pixels", "a non-negative integer",
             min_region_pixels);
  CheckRange(min_object_pixels >= 1, "min_object_pixels", "a positive integer",
             min_object_pixels);
}

namespace {

constexpr int kHistogramBins = 256;

// Histogram of the finite values of a CV_32FC1 image over [lo, the 99.9th percentile]
// (values above fall into the last bin); false when the values are constant.
bool Histogram(const cv::Mat& values, std::vector<double>* counts, double* lo, double* bin_width) {
  SUBFLOW_CHECK(values.type() == CV_32FC1, "automatic thresholds expect CV_32FC1");
  std::vector<float> finite;
  finite.reserve(values.total());
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    for (int x = 0; x < values.cols; ++x)
      if (std::isfinite(row[x])) finite.push_back(row[x]);
  }
  if (finite.empty()) {
    *lo = 0;
    return false;
  }
  *lo = *std::min_element(finite.begin(), finite.end());
  // The top of the histogram is a high percentile, not the maximum, so that a few
  // outliers do not squeeze the object's values into the lowest bins.
  std::vector<float> sorted = finite;
  const size_t top = std::min(sorted.size() - 1, static_cast<size_t>(0.999 * sorted.size()));
  std::nth_element(sorted.begin(), sorted.begin() + top, sorted.end());
  double hi = sorted[top];
  if (!(hi > *lo)) hi = *std::max_element(finite.begin(), finite.end());
  if (!(hi > *lo)) return false;
  counts->assign(kHistogramBins, 0.0);
  *bin_width = (hi - *lo) / kHistogramBins;
  for (float v : finite)
    (*counts)[std::clamp(static_cast<int>((v - *lo) / *bin_width), 0, kHistogramBins - 1)] += 1.0;
  return true;
}

}  // namespace

double OtsuThreshold(const cv::Mat& values) {
  std::vector<double> histogram;
  double lo = 0, bin_width = 0;
  if (!Histogram(values, &histogram, &lo, &bin_width)) return lo;
  double total = 0, sum_all = 0;
  for (int b = 0; b < kHistogramBins; ++b) total += histogram[b], sum_all += b * histogram[b];
  double weight_low = 0, sum_low = 0, best_variance = -1;
  int best_bin = 0;
  for (int b = 0; b < kHistogramBins - 1; ++b) {
    weight_low += histogram[b];
    sum_low += b * histogram[b];
    const double weight_high = total - weight_low;
    if (weight_low == 0 || weight_high == 0) continue;
    const double mean_low = sum_low / weight_low;
    const double mean_high = (sum_all - sum_low) / weight_high;
    const double variance = weight_low * weight_high * (mean_low - mean_high) * (mean_low - mean_high);
    if (variance > best_variance) {
      best_variance = variance;
      best_bin = b;
    }
  }
  // The classes are {bins ≤ best_bin} and {bins > best_bin}: threshold at the bin's top edge.
  return lo + (best_bin + 1) * bin_width;
}

double TriangleThreshold(const cv::Mat& values) {
  std::vector<double> histogram;
  double lo = 0, bin_width = 0;
  if (!Histogram(values, &histogram, &lo, &bin_width)) return lo;
  const int peak = static_cast<int>(std::max_element(histogram.begin(), histogram.end()) - histogram.begin());
  int end = kHistogramBins - 1;  // the tail's end: the last non-empty bin above the peak
  while (end > peak && histogram[end] == 0) --end;
  if (end == peak) return lo + (peak + 1) * bin_width;
  // The bin farthest below the chord from (peak, h[peak]) to (end, h[end]).
  const double dx = end - peak, dy = histogram[end] - histogram[peak];
  double best_distance = -1;
  int best_bin = peak;
  for (int b = peak + 1; b <= end; ++b) {
    const double distance = dy * (b - peak) - dx * (histogram[b] - histogram[peak]);  // ∝ distance below
    if (distance > best_distance) {
      best_distance = distance;
      best_bin = b;
    }
  }
  return lo + best_bin * bin_width;
}

namespace {

cv::Mat Disk(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

// Sets the mask and what follows from it: evidence, object_pixels, empty.
void SetMask(const cv::Mat& mask, const SilhouetteOptions& options, Silhouette* silhouette) {
  silhouette->mask = mask;
  mask.convertTo(silhouette->evidence, CV_32F, 1.0 / 255.0);
  silhouette->object_pixels = cv::countNonZero(mask);
  silhouette->empty = silhouette->object_pixels < options.min_object_pixels;
}

}  // namespace

Silhouette ThresholdAndClean(const cv::Mat& measure, double threshold,
                             const SilhouetteOptions& options, int open_radius, double close_floor,
                             bool open_seen_through_holes) {
  SUBFLOW_CHECK(measure.type() == CV_32FC1, "ThresholdAndClean expects CV_32FC1");
  Silhouette silhouette;
  silhouette.measure = measure;
  silhouette.threshold = threshold;
  cv::Mat mask = measure > threshold;  // CV_8U 0 / 255
  if (open_radius > 0) cv::morphologyEx(mask, mask, cv::MORPH_OPEN, Disk(open_radius));
  if (options.close_radius > 0) {
    cv::Mat closed;
    cv::morphologyEx(mask, closed, cv::MORPH_CLOSE, Disk(options.close_radius));
    if (close_floor > 0) closed &= mask | (measure >= close_floor);
    mask = closed;
  }
  if (options.min_region_pixels > 1) RemoveSmallRegions(&mask, options.min_region_pixels);
  if (options.fill_holes)
    FillHoles(&mask, measure, open_seen_through_holes ? close_floor : 0.0, options.min_region_pixels);
  SetMask(mask, options, &silhouette);
  return silhouette;
}

cv::Mat HalfContrastContour(const cv::Mat& measure, const cv::Mat& mask, double fraction) {
  SUBFLOW_CHECK(measure.type() == CV_32FC1 && mask.type() == CV_8UC1 && measure.size() == mask.size(),
                "HalfContrastContour expects a CV_32FC1 measure and a CV_8UC1 mask of one size");
  constexpr int kBand = 2, kInterior = 3, kWindow = 5;  // pixels
  cv::Mat band, interior;
  cv::erode(mask, band, Disk(kBand), cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  band = mask & ~band;
  cv::erode(mask, interior, Disk(kInterior), cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  cv::Mat weight, weighted_sum, weight_sum;
  interior.convertTo(weight, CV_32F, 1.0 / 255.0);
  const cv::Size window(2 * kWindow + 1, 2 * kWindow + 1);
  cv::boxFilter(measure.mul(weight), weighted_sum, CV_32F, window, cv::Point(-1, -1), false);
  cv::boxFilter(weight, weight_sum, CV_32F, window, cv::Point(-1, -1), false);
  cv::Mat refined = mask.clone();
  for (int y = 0; y < mask.rows; ++y) {
    const uint8_t* band_row = band.ptr<uint8_t>(y);
    const float* value = measure.ptr<float>(y);
    const float* sum = weighted_sum.ptr<float>(y);
    const float* count = weight_sum.ptr<float>(y);
    uint8_t* row = refined.ptr<uint8_t>(y);
    for (int x = 0; x < mask.cols; ++x)
      if (band_row[x] && count[x] > 0 && value[x] < fraction * sum[x] / count[x]) row[x] = 0;
  }
  return refined;
}

Silhouette SilhouetteFromMask(const cv::Mat& mask, const SilhouetteOptions& options) {
  if (mask.empty() || mask.type() != CV_8UC1)
    ThrowError("", "mask", "expected a non-empty CV_8UC1 image");
  Silhouette silhouette;
  silhouette.source = EvidenceSource::kMask;
  silhouette.mask = mask != 0;
  silhouette.mask.convertTo(silhouette.evidence, CV_32F, 1.0 / 255.0);
  silhouette.measure = silhouette.evidence;
  silhouette.threshold = 0.5;
  silhouette.object_pixels = cv::countNonZero(silhouette.mask);
  silhouette.empty = silhouette.object_pixels < options.min_object_pixels;
  return silhouette;
}

cv::Mat BackgroundDifference(const cv::Mat& image, const cv::Mat& background) {
  if (image.empty() || image.size() != background.size() || image.type() != background.type())
    ThrowError("", "background",
               "expected an image of the same size and type as the frame, got " +
                   std::to_string(background.cols) + "×" + std::to_string(background.rows) +
                   " vs " + std::to_string(image.cols) + "×" + std::to_string(image.rows));
  const cv::Mat a = ToUnitFloat(image), b = ToUnitFloat(background);
  cv::Mat difference = a - b;
  difference = difference.mul(difference);
  cv::Mat squared;
  if (difference.channels() == 1) {
    squared = difference;
  } else {
    cv::transform(difference, squared, cv::Matx13f(1.f, 1.f, 1.f) * (1.f / 3.f));
  }
  cv::Mat distance;
  cv::sqrt(squared, distance);
  return distance;
}

namespace {

// The threshold of a background difference: fixed, else per camera from the noise of the
// surely-background pixels (vision/silhouettes_background.h), else the histogram's.
double BackgroundThreshold(const cv::Mat& smoothed_difference, const cv::Mat& surely_background,
                           const SilhouetteOptions& options) {
  if (options.background_threshold >= 0) return options.background_threshold;
  const NoiseThreshold noise = EstimateNoiseThreshold(smoothed_difference, surely_background, options);
  if (noise.valid) return noise.threshold;
  return AutomaticThreshold(smoothed_difference, -1.0, options.background_method, options.background_min_threshold);
}

// Thresholds the shadow-robust difference of `image` to `background` (both CV_32F in
// [0, 1]), cleans and corrects the contour; pixels of `unknown` (CV_8UC1, may be empty)
// count as object.
Silhouette SilhouetteFromDifference(const cv::Mat& image, const cv::Mat& background, const cv::Mat& unknown,
                                    const cv::Mat& surely_background, const SilhouetteOptions& options) {
  cv::Mat plain = BackgroundDifference(image, background);
  if (!unknown.empty()) plain.setTo(1.0f, unknown);
  const double threshold = BackgroundThreshold(Smooth(plain, options.background_blur_sigma), surely_background, options);
  cv::Mat difference = options.background_shadow_test ? ShadowRobustDifference(image, background, threshold, options)
                                                      : plain;
  if (!unknown.empty()) difference.setTo(1.0f, unknown);
  const cv::Mat measure = Smooth(difference, options.background_blur_sigma);
  // A background of one colour is a plain backdrop (BackdropImage): a hole of its colour is
  // the backdrop seen through. Behind a photographed room, parts of the object that match
  // what lies behind them would open as well (bust_front_nomasks 0.97 → 2.02 mm).
  Silhouette silhouette = ThresholdAndClean(measure, threshold, options, options.background_open_radius,
                                            options.background_close_floor * threshold, OneColour(background));
  silhouette.source = EvidenceSource::kBackground;
  if (options.background_contour_fraction > 0)
    SetMask(HalfContrastContour(measure, silhouette.mask, options.background_contour_fraction), options,
            &silhouette);
  return silhouette;
}

}  // namespace

Silhouette SilhouetteFromBackground(const cv::Mat& image, const cv::Mat& background,
                                    const SilhouetteOptions& options, const cv::Mat& surely_background) {
  return SilhouetteFromDifference(ToUnitFloat(image), ToUnitFloat(background), cv::Mat(), surely_background,
                                  options);
}

cv::Mat MotionEvidence(const std::vector<cv::Mat>& gray_frames, int index,
                       const SilhouetteOptions& options) {
  const int count = static_cast<int>(gray_frames.size());
  if (count < 2)
    ThrowError("", "motion evidence", "expected at least 2 frames, got " + std::to_string(count));
  SUBFLOW_CHECK(index >= 0 && index < count, "frame index outside the sequence");
  for (const cv::Mat& frame : gray_frames)
    if (frame.type() != CV_32FC1 || frame.size() != gray_frames[0].size())
      ThrowError("", "motion evidence", "expected CV_32FC1 gray frames of one size");
  const int first = std::max(0, index - options.motion_window);
  const int last = std::min(count - 1, index + options.motion_window);
  // Smoothed frames g − 1 .. g + 1 for every g of the window.
  const int smooth_first = std::max(0, first - 1), smooth_last = std::min(count - 1, last + 1);
  std::vector<cv::Mat> smoothed(count);
  for (int g = smooth_first; g <= smooth_last; ++g)
    smoothed[g] = Smooth(gray_frames[g], options.motion_sigma);

  cv::Mat accumulated = cv::Mat::zeros(gray_frames[0].size(), CV_32F);
  for (int g = first; g <= last; ++g) {
    const int before = std::max(0, g - 1), after = std::min(count - 1, g + 1);
    cv::Mat dt = (smoothed[after] - smoothed[before]) / static_cast<double>(after - before);
    cv::Mat dx, dy;
    cv::Sobel(smoothed[g], dx, CV_32F, 1, 0, 1, 0.5, 0, cv::BORDER_REPLICATE);
    cv::Sobel(smoothed[g], dy, CV_32F, 0, 1, 1, 0.5, 0, cv::BORDER_REPLICATE);
    cv::Mat denominator = dx.mul(dx) + dy.mul(dy) + options.motion_lambda;
    cv::Mat theta;
    cv::divide(cv::abs(dt), denominator, theta);
    cv::max(accumulated, theta, accumulated);
  }
  return accumulated;
}

Silhouette SilhouetteFromMotion(const std::vector<cv::Mat>& gray_frames, int index,
                                const SilhouetteOptions& options) {
  const cv::Mat measure = MotionEvidence(gray_frames, index, options);
  const double threshold =
      AutomaticThreshold(measure, options.motion_threshold, options.motion_method, options.motion_min_threshold);
  Silhouette silhouette = ThresholdAndClean(measure, threshold, options);
  silhouette.source = EvidenceSource::kMotion;
  return silhouette;
}

EstimatedBackground EstimateBackground(const std::vector<cv::Mat>& images,
                                       const std::vector<cv::Mat>& gray_frames,
                                       const SilhouetteOptions& options) {
  const int count = static_cast<int>(images.size());
  if (count < 2 || gray_frames.size() != images.size())
    ThrowError("", "background estimate",
               "expected at least 2 frames and as many gray frames, got " + std::to_string(count) + " and " +
                   std::to_string(gray_frames.size()));
  std::vector<cv::Mat> frames(count), free(count);
  bool moves = false;
  for (int g = 0; g < count; ++g) {
    frames[g] = ToUnitFloat(images[g]);
    if (frames[g].size() != frames[0].size() || frames[g].type() != frames[0].type() ||
        gray_frames[g].size() != frames[0].size())
      ThrowError("", "background estimate", "expected frames of one size and type");
    const Silhouette motion = SilhouetteFromMotion(gray_frames, g, options);
    moves = moves || !motion.empty;
    cv::Mat object = motion.mask;
    if (options.background_estimate_margin > 0)
      cv::dilate(object, object, Disk(options.background_estimate_margin));
    free[g] = object == 0;
  }
  EstimatedBackground result;
  if (!moves) return result;  // nothing moves: the "background" would be the object too
  const int channels = frames[0].channels(), rows = frames[0].rows, cols = frames[0].cols;
  result.frames = count;
  result.image = cv::Mat::zeros(rows, cols, frames[0].type());
  result.known = cv::Mat::zeros(rows, cols, CV_8UC1);
  std::vector<float> values(count);
  long known = 0, free_total = 0;
  for (int y = 0; y < rows; ++y) {
    float* out = result.image.ptr<float>(y);
    uint8_t* known_row = result.known.ptr<uint8_t>(y);
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < channels; ++c) {
        int n = 0;
        for (int g = 0; g < count; ++g)
          if (free[g].at<uint8_t>(y, x)) values[n++] = frames[g].ptr<float>(y)[x * channels + c];
        if (n == 0) break;
        // The lower median (an even count takes the lower of the two middle values).
        std::nth_element(values.begin(), values.begin() + (n - 1) / 2, values.begin() + n);
        out[x * channels + c] = values[(n - 1) / 2];
        if (c == 0) {
          known_row[x] = 255;
          ++known;
          free_total += n;
        }
      }
    }
  }
  // Instability: the median absolute deviation of the gray free samples from their median.
  result.instability = cv::Mat::zeros(rows, cols, CV_32FC1);
  for (int y = 0; y < rows; ++y) {
    float* out = result.instability.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      int n = 0;
      for (int g = 0; g < count; ++g)
        if (free[g].at<uint8_t>(y, x)) values[n++] = gray_frames[g].at<float>(y, x);
      if (n == 0) continue;
      std::nth_element(values.begin(), values.begin() + (n - 1) / 2, values.begin() + n);
      const float median = values[(n - 1) / 2];
      for (int i = 0; i < n; ++i) values[i] = std::abs(values[i] - median);
      std::nth_element(values.begin(), values.begin() + (n - 1) / 2, values.begin() + n);
      out[x] = values[(n - 1) / 2];
    }
  }
  result.known_fraction = static_cast<double>(known) / (static_cast<double>(rows) * cols);
  result.mean_free_frames = known > 0 ? static_cast<double>(free_total) / known : 0.0;
  return result;
}

Silhouette SilhouetteFromEstimatedBackground(const cv::Mat& image, const EstimatedBackground& background,
                                             const SilhouetteOptions& options) {
  SUBFLOW_CHECK(background.valid(), "SilhouetteFromEstimatedBackground without a background");
  // An estimated background is a median of the take's own frames: its pixels near the
  // subject are less certain than a photographed background, and on the synthetic take
  // take_small (scripts/make_scenes.sh) the noise threshold and the shadow test emptied
  // the hull. Here the plain difference and the histogram threshold, as before, until a
  // rule holds for both. For the same reason the plain closing: the subject's parts
  // differ from such a background by little, and with background_close_floor the closing
  // no longer joined them — on pose2sim_multiperson the man's standing shin and foot fell
  // out of frame 50's hull in two cameras (docs/shape.md, "Gaps between limbs").
  SilhouetteOptions plain = options;
  plain.background_shadow_test = false;
  plain.background_close_floor = 0;
  return SilhouetteFromDifference(ToUnitFloat(image), background.image, background.known == 0, cv::Mat(), plain);
}

}  // namespace subflow::vision
