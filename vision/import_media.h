// Finding each calibrated camera's frames for `subflow import` (docs/import.md):
//
//   name matching   an entry (file stem, or folder name) of the media folder belongs to
//                   camera N when
//                   (a) a --name-pattern regex is given: its first capture group (or the
//                       whole match when it has none), searched in the entry, equals N;
//                   (b) otherwise the entry equals N; failing that for camera N, the entry
//                       contains N as a token (bounded by the ends or by characters other
//                       than letters and digits: "hd_00_01" holds "00_01", "cam1" does not
//                       hold "1").
//                   A camera matched by several entries, or an entry by several cameras, is
//                   an error naming both.
//   videos          regular files of the folder (any container VideoCapture opens).
//   images          a folder matching N holds N's frames (image files, natural order);
//                   a file matching N is a one-frame still; when nothing matches and the
//                   calibration names an image for N (COLMAP, Middlebury), that path below
//                   the folder is N's still.
#pragma once

#include <string>
#include <vector>

#include "vision/calibration_import.h"

namespace subflow::vision {

// Index into `entries` of each camera's entry (−1 when none), by the rule above. Throws
// subflow::Error naming `folder` on ambiguity or an invalid pattern.
std::vector<int> MatchCameraNames(const std::vector<std::string>& cameras, const std::vector<std::string>& entries,
                                  const std::string& name_pattern, const std::string& folder);

struct CameraMedia {
  std::string camera;
  bool video = false;
  std::vector<std::string> files;  // the video, or the images in frame order (absolute paths)
  int width = 0, height = 0;       // as decoded (the first image; every image is checked)
  int frame_count = 0;             // video: as its container reports it; images: #files
  double fps = 0;                  // video: as reported (0 = unknown); images: 0
};

struct MediaSearch {
  std::vector<CameraMedia> media;         // per camera of the calibration, "" camera when unmatched
  std::vector<std::string> unused;        // entries of the folder that match no camera
};

// Searches `videos` or `images` (exactly one non-empty) for every camera of `calibration`.
MediaSearch FindCameraMedia(const Calibration& calibration, const std::string& videos, const std::string& images,
                            const std::string& name_pattern);

// Image extensions read from --images folders (lower case, with the dot).
bool IsImageExtension(const std::string& extension);

}  // namespace subflow::vision
