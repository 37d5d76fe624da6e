// The background difference that holds on textured floors and under soft shadows
// (issue 12 item 4): a comparison a shadow cannot fool, and a threshold per camera from
// the noise of the pixels that are surely background.
//
// Shadow-robust difference. A shadow (or a change of exposure) leaves a surface's colour
// and texture as they were and scales its radiance by a gain α: in linear radiance
// I(p) ≈ α·B(p) in every channel, with α smooth in space. An object replaces the
// background: its colour, its texture, or both differ. Images are sRGB-encoded (cameras
// and the renderer, vision/synthetic_render.h), so the gain acts on the decoded values
// L = sRGB⁻¹(V); differences are still measured in encoded units (where sensor noise and
// the thresholds live), through the encoding's slope s = dV/dL at the image's value:
//     a_c(p) = s(L^I_c(p))·L^I_c(p),   b_c(p) = s(L^I_c(p))·L^B_c(p),
//     r_c(p; α) = a_c(p) − α·b_c(p) ≈ V^I_c(p) − sRGB(α·L^B_c(p))   (to first order),
// the misfit of "p is the background under gain α" in encoded units, channel c.
//
// Windows. Around every pixel q: the square W(q) of (2w + 1)² pixels (w =
// shadow_window_radius), over which the gain may tilt, g_q(p) = α + β·u + γ·v with
// (u, v) = (p − q) / w (a penumbra crossing it), and four lines of 2w + 1 pixels through q
// (horizontal, vertical, both diagonals) with one gain g_q = α: a sharp shadow edge or a
// thin shadow (a leg's, a few pixels wide) is fitted by no square but lies along a line.
// Each window's gain is the least-squares fit over its pixels and channels,
//     θ = argmin Σ_W Σ_c r_c(p; g_q(p))²,     R(q) = that minimum / (C·|W|),
// (window sums by correlation, a 3×3 solve per square), and the window is a shadow
// window when α ∈ [shadow_min_gain, shadow_max_gain] and √R(q) ≤ τ (τ = the camera's
// threshold): one gain explains the colours AND the texture of all its pixels. This is
// where texture counts: on a textured floor, a window that the object covers is fitted by
// no gain (its gradients are not the background's), while a shadow's window is.
// The shadow-robust difference of a pixel is what the best shadow window containing it
// leaves unexplained:
//     e(p) = min over shadow windows W ∋ p of √(Σ_c r_c(p; g_W(p))² / C)
//            (the window gain nearest p's own gain Σ_c a·b / Σ_c b²),
//     m(p) = min(d(p), e(p)),   d(p) = the plain colour difference (BackgroundDifference).
// Only windows that contain p and fit are used, so a background pixel next to the object
// keeps a small e through a window on its far side (no widening of the silhouette), and a
// pixel the object half covers keeps the half contrast HalfContrastContour relies on.
// What it cannot tell apart: an object of the background's colour that is darker by a
// gain in [shadow_min_gain, 1] over a region of the background without texture (a gray
// object on a flat gray wall looks like its shadow); a textured background tells them
// apart, colour (cameras that have it) helps.
//
// Per-camera threshold. The pixels outside the projection of the working volume (the
// dataset's bounds, grown by working_volume_margin) cannot show the object: their plain
// difference d is the camera's noise (sensor noise of image and background, compression,
// small misregistration), and distractors outside the volume, which a robust statistic
// ignores. The threshold is
//     t = max(background_min_threshold, median(d) + background_noise_factor · 1.4826 · MAD(d))
// over those pixels (MAD = median absolute deviation from the median): each camera gets
// a threshold that follows its own noise. Too few such pixels (the volume fills the
// image): the automatic histogram threshold (TriangleThreshold) as before.
#pragma once

#include <opencv2/core.hpp>

#include "vision/silhouettes.h"

namespace subflow::vision {

class Camera;
struct Bounds;

// Decoded (linear) values of sRGB-encoded values in [0, 1], any channel count, CV_32F.
cv::Mat DecodeSrgb(const cv::Mat& encoded);

// The shadow-robust difference m (file comment) of an image to its background: CV_32FC1
// in [0, 1]. `image`, `background`: same size and type (CV_8U, CV_16U or CV_32F in [0, 1];
// 1, 3 or 4 channels, alpha ignored). `tolerance`: τ, the largest RMS misfit (encoded
// units) of a shadow window. Without options.background_shadow_test, d itself.
cv::Mat ShadowRobustDifference(const cv::Mat& image, const cv::Mat& background, double tolerance,
                               const SilhouetteOptions& options = {});

// CV_8UC1 of the camera's size: 255 where a pixel surely shows background, i.e. lies
// farther than `margin_pixels` from the projection of the box `bounds` (its 12 edges,
// sampled and projected with Camera::Project, lens distortion included; the convex hull
// of those points). Empty (all 0) when a corner of the box is behind the camera or does
// not project: then nothing is surely background.
cv::Mat OutsideWorkingVolume(const Camera& camera, const Bounds& bounds, double margin_pixels);

// The per-camera noise threshold of a plain difference image (file comment).
struct NoiseThreshold {
  bool valid = false;      // enough surely-background pixels (else use the histogram threshold)
  double threshold = 0;    // t
  double median = 0;       // median(d) over the surely-background pixels
  double sigma = 0;        // 1.4826 · MAD(d)
  long pixels = 0;         // surely-background pixels used
};
// `difference`: CV_32FC1 (the plain difference d, blurred as the measure is);
// `surely_background`: CV_8UC1 of the same size (OutsideWorkingVolume) or empty.
// Valid when at least options.min_background_pixels pixels are surely background.
NoiseThreshold EstimateNoiseThreshold(const cv::Mat& difference, const cv::Mat& surely_background,
                                      const SilhouetteOptions& options = {});

}  // namespace subflow::vision
