// Working image scale: HD frames reduced to the resolution a stage can use, so that a
// 1088×1920 take costs about what the same object costs at 320×240 where the extra pixels
// carry nothing the stage resolves (issue 13, item 4).
//
// A working camera is the stored camera for its image resized by cv::resize to
// (round(s·w), round(s·h)) with s ≤ 1: per axis a = w'/w (b = h'/h), the pixel-centre
// convention maps a stored pixel x to a (x + ½) − ½, so K' = diag(a, b, 1)·K with
// c' = a (c + ½) − ½ (the same rule as the importer's rescaling of binned video). The lens
// distortion acts in normalized coordinates and stays as it is.
//
// How s is chosen (never above 1, so small images are left alone):
//  - evidence (silhouettes, background, carving): the voxel of the carving grid should
//    span `voxel_pixels` pixels of the working image at the volume's centre; more pixels
//    per voxel only cost time (a voxel's evidence is the mean over its footprint);
//  - images of motion and stereo: the finest level's edges of the surface should project
//    to `edge_pixels` pixels (median over the vertices the camera sees in front of it);
//    finer images hold detail the surface cannot represent.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "geometry/triangle_mesh.h"
#include "vision/camera.h"
#include "vision/working_volume.h"

namespace subflow::vision {

// The camera of `camera`'s images resized by `scale` ∈ (0, 1] (1 returns the camera).
Camera ScaledCamera(const Camera& camera, double scale);
// `image` (of `stored`'s size) resized to `working`'s size: cv::INTER_AREA; with `mask`
// the result is thresholded back to 0 / 255 at half coverage. Returns `image` itself when
// the sizes agree.
cv::Mat ResizeToCamera(const cv::Mat& image, const Camera& working, bool mask = false);

// The scale of the evidence images of `camera`: min(1, voxel_pixels / p), p = the pixels
// one voxel of edge `voxel_size` spans at the volume's centre (f · voxel_size / depth);
// 1 when the centre is behind the camera or voxel_pixels ≤ 0.
double EvidenceScale(const Camera& camera, const Bounds& bounds, double voxel_size, double voxel_pixels);

// The scale of `camera`'s images for a surface (V, F): min(1, edge_pixels / e), e = the
// median projected length (pixels, undistorted) of the edges whose both ends are in front
// of the camera and project into the image; 1 when there are none or edge_pixels ≤ 0.
// `median_pixels`, when given, receives e (0 when there are none).
double SurfaceScale(const Camera& camera, const geometry::Positions& V, const geometry::Faces& F,
                    double edge_pixels, double* median_pixels = nullptr);

// The cameras with ScaledCamera applied (scales[k] for camera k).
std::vector<Camera> ScaledCameras(const std::vector<Camera>& cameras, const std::vector<double>& scales);

}  // namespace subflow::vision
