#include "vision/standing_evidence.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace subflow::vision {

void StandingEvidenceOptions::Check() const {
  const std::string source = "standing evidence options";
  if (!(noise_factor >= 1 && noise_factor <= 1000)) ThrowError(source, "noise_factor", "expected a value in [1, 1000]");
  if (!(min_threshold >= 0 && min_threshold < 1)) ThrowError(source, "min_threshold", "expected a value in [0, 1)");
}

Silhouette StandingSilhouette(const EstimatedBackground& background, const SilhouetteOptions& silhouettes,
                              const StandingEvidenceOptions& options) {
  options.Check();
  Silhouette result;
  result.source = EvidenceSource::kBackground;
  if (!background.valid() || background.instability.empty()) return result;
  const cv::Mat& instability = background.instability;
  std::vector<float> values;
  values.reserve(instability.total());
  for (int y = 0; y < instability.rows; ++y)
    for (int x = 0; x < instability.cols; ++x)
      if (background.known.at<uchar>(y, x)) values.push_back(instability.at<float>(y, x));
  if (values.empty()) return result;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double threshold = std::max(options.min_threshold, options.noise_factor * values[values.size() / 2]);
  cv::Mat measure = instability.clone();
  measure.setTo(0.0f, background.known == 0);  // unknown pixels are the difference silhouette's affair
  // No opening: like motion evidence, the sway shows as thin bands along outlines and edges.
  result = ThresholdAndClean(measure, threshold, silhouettes, 0);
  result.source = EvidenceSource::kBackground;
  return result;
}

void AddStandingEvidence(const std::vector<Silhouette>& standing, std::vector<Silhouette>* silhouettes) {
  SUBFLOW_CHECK(standing.size() == silhouettes->size(), "one standing silhouette per camera");
  for (std::size_t k = 0; k < standing.size(); ++k) {
    if (standing[k].empty) continue;
    Silhouette& silhouette = (*silhouettes)[k];
    SUBFLOW_CHECK(standing[k].mask.size() == silhouette.mask.size(), "standing silhouette of the camera's size");
    cv::bitwise_or(silhouette.mask, standing[k].mask, silhouette.mask);
    silhouette.mask.convertTo(silhouette.evidence, CV_32F, 1.0 / 255.0);
    silhouette.object_pixels = cv::countNonZero(silhouette.mask);
    silhouette.empty = false;  // it holds the standing silhouette, which is not empty
  }
}

}  // namespace subflow::vision
