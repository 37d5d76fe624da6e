#include "vision/import_media.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <regex>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/error.h"
#include "core/file_status.h"
#include "vision/natural_order.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

bool Alphanumeric(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

bool ContainsToken(const std::string& entry, const std::string& name) {
  for (std::size_t at = entry.find(name); at != std::string::npos; at = entry.find(name, at + 1)) {
    const bool start = at == 0 || !Alphanumeric(entry[at - 1]);
    const std::size_t end = at + name.size();
    if (start && (end == entry.size() || !Alphanumeric(entry[end]))) return true;
  }
  return false;
}

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

bool Hidden(const fs::path& path) { return path.filename().string().rfind('.', 0) == 0; }

std::vector<std::string> ImagesIn(const fs::path& folder) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (!Hidden(entry.path()) && IsFile(entry.path()) && IsImageExtension(Lower(entry.path().extension().string())))
      files.push_back(fs::absolute(entry.path()).lexically_normal().string());
  std::sort(files.begin(), files.end(), NaturalLess);
  return files;
}

CameraMedia ProbeVideo(const std::string& camera, const fs::path& path) {
  CameraMedia media;
  media.camera = camera;
  media.video = true;
  media.files = {fs::absolute(path).lexically_normal().string()};
  cv::VideoCapture capture(path.string());
  if (!capture.isOpened())
    ThrowError(path.string(), "", "unreadable video (expected a file OpenCV's VideoCapture reads)");
  media.width = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_WIDTH));
  media.height = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_HEIGHT));
  media.frame_count = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_COUNT));
  media.fps = capture.get(cv::CAP_PROP_FPS);
  if (media.width <= 0 || media.height <= 0) ThrowError(path.string(), "size", "unknown (the container does not report it)");
  return media;
}

CameraMedia ProbeImages(const std::string& camera, std::vector<std::string> files, const std::string& where) {
  CameraMedia media;
  media.camera = camera;
  media.files = std::move(files);
  if (media.files.empty())
    ThrowError(where, "", "no image files for camera \"" + camera + "\" (expected .png, .jpg, .tif, ... files)");
  for (const std::string& file : media.files) {
    const cv::Mat image = cv::imread(file, cv::IMREAD_UNCHANGED);
    if (image.empty()) ThrowError(file, "", "unreadable image (cv::imread failed)");
    if (media.width == 0) {
      media.width = image.cols;
      media.height = image.rows;
    } else if (image.cols != media.width || image.rows != media.height) {
      ThrowError(file, "size", "expected " + std::to_string(media.width) + "×" + std::to_string(media.height) +
                                   " like " + media.files.front() + ", got " + std::to_string(image.cols) + "×" +
                                   std::to_string(image.rows));
    }
  }
  media.frame_count = static_cast<int>(media.files.size());
  return media;
}

}  // namespace

bool IsImageExtension(const std::string& extension) {
  static const char* const kExtensions[] = {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".ppm", ".pgm", ".webp"};
  return std::find(std::begin(kExtensions), std::end(kExtensions), extension) != std::end(kExtensions);
}

std::vector<int> MatchCameraNames(const std::vector<std::string>& cameras, const std::vector<std::string>& entries,
                                  const std::string& name_pattern, const std::string& folder) {
  std::vector<int> match(cameras.size(), -1);
  std::vector<std::string> pattern_names(entries.size());
  if (!name_pattern.empty()) {
    std::regex pattern;
    try {
      pattern = std::regex(name_pattern);
    } catch (const std::regex_error& e) {
      ThrowError("--name-pattern", "\"" + name_pattern + "\"", std::string("expected a regular expression: ") + e.what());
    }
    for (std::size_t e = 0; e < entries.size(); ++e) {
      std::smatch found;
      if (std::regex_search(entries[e], found, pattern)) pattern_names[e] = found.size() > 1 ? found[1].str() : found[0].str();
    }
  }
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    std::vector<int> candidates;
    for (std::size_t e = 0; e < entries.size(); ++e)
      if (name_pattern.empty() ? entries[e] == cameras[c] : pattern_names[e] == cameras[c])
        candidates.push_back(static_cast<int>(e));
    if (candidates.empty() && name_pattern.empty())
      for (std::size_t e = 0; e < entries.size(); ++e)
        if (ContainsToken(entries[e], cameras[c])) candidates.push_back(static_cast<int>(e));
    if (candidates.size() > 1)
      ThrowError(folder, "camera \"" + cameras[c] + "\"",
                 "matched by several entries (\"" + entries[candidates[0]] + "\", \"" + entries[candidates[1]] +
                     "\"); expected one (give --name-pattern)");
    if (!candidates.empty()) match[c] = candidates[0];
  }
  for (std::size_t a = 0; a < cameras.size(); ++a)
    for (std::size_t b = a + 1; b < cameras.size(); ++b)
      if (match[a] >= 0 && match[a] == match[b])
        ThrowError(folder, "\"" + entries[match[a]] + "\"",
                   "matches cameras \"" + cameras[a] + "\" and \"" + cameras[b] + "\"; expected one (give --name-pattern)");
  return match;
}

MediaSearch FindCameraMedia(const Calibration& calibration, const std::string& videos, const std::string& images,
                            const std::string& name_pattern) {
  const bool use_videos = !videos.empty();
  const fs::path folder(use_videos ? videos : images);
  if (!IsDirectory(folder))
    ThrowError(folder.string(), "", use_videos ? "not a directory (expected a folder of one video per camera)"
                                               : "not a directory (expected a folder of images per camera)");
  std::vector<fs::path> paths;
  std::vector<std::string> entries;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (Hidden(entry.path())) continue;
    const bool directory = IsDirectory(entry.path());
    if (use_videos ? !IsFile(entry.path())
                   : !(directory || (IsFile(entry.path()) &&
                                     IsImageExtension(Lower(entry.path().extension().string())))))
      continue;
    paths.push_back(entry.path());
    entries.push_back(directory ? entry.path().filename().string() : entry.path().stem().string());
  }
  std::vector<std::string> names;
  for (const CalibratedCamera& camera : calibration.cameras) names.push_back(camera.name);
  const std::vector<int> match = MatchCameraNames(names, entries, name_pattern, folder.string());

  MediaSearch search;
  search.media.resize(names.size());
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (match[c] < 0) {
      const std::string& hint = calibration.cameras[c].image_name;
      if (!use_videos && !hint.empty() && IsFile(folder / hint))
        search.media[c] = ProbeImages(names[c], {fs::absolute(folder / hint).lexically_normal().string()},
                                      (folder / hint).string());
      continue;
    }
    const fs::path& path = paths[match[c]];
    if (use_videos) search.media[c] = ProbeVideo(names[c], path);
    else if (IsDirectory(path)) search.media[c] = ProbeImages(names[c], ImagesIn(path), path.string());
    else search.media[c] = ProbeImages(names[c], {fs::absolute(path).lexically_normal().string()}, path.string());
  }
  for (std::size_t e = 0; e < entries.size(); ++e)
    if (std::find(match.begin(), match.end(), static_cast<int>(e)) == match.end())
      search.unused.push_back(paths[e].filename().string());
  std::sort(search.unused.begin(), search.unused.end(), NaturalLess);
  return search;
}

}  // namespace subflow::vision
