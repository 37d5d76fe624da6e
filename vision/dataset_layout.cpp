#include "vision/dataset_layout.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/error.h"
#include "core/file_status.h"
#include "vision/import_media.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

std::string Str(const fs::path& path) { return path.string(); }

bool Hidden(const fs::path& path) { return path.filename().string().rfind('.', 0) == 0; }

std::string SizeText(int width, int height) {
  return std::to_string(width) + "×" + std::to_string(height);
}

std::string JoinedNames(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::string CameraList(const std::vector<Camera>& cameras) {
  std::vector<std::string> names;
  for (const Camera& camera : cameras) names.push_back(camera.name());
  return JoinedNames(names);
}

// Frame index of "<6 digits><extension>", or -1.
int FrameIndex(const std::string& file_name, const std::string& extension) {
  if (file_name.size() != 6 + extension.size() || file_name.compare(6, std::string::npos, extension) != 0)
    return -1;
  for (int i = 0; i < 6; ++i)
    if (!std::isdigit(static_cast<unsigned char>(file_name[i]))) return -1;
  return std::stoi(file_name.substr(0, 6));
}

// A PNG's pixel format as its IHDR chunk states it.
struct PngFormat {
  int bit_depth = 8;
  int colour_type = 0;  // 0 gray, 2 RGB, 3 palette, 4 gray + alpha, 6 RGBA
  bool operator<(const PngFormat& other) const {
    return std::tie(bit_depth, colour_type) < std::tie(other.bit_depth, other.colour_type);
  }
  std::string Text() const {
    const char* kind = colour_type == 0 ? "gray" : colour_type == 3 ? "palette" : colour_type == 4 ? "gray + alpha"
                                                                                                   : "colour";
    return std::to_string(bit_depth) + "-bit " + kind;
  }
};

// Width and height from a PNG's IHDR chunk (the first 26 bytes), checked against the
// camera; returns the pixel format (bit depth, colour type) that follows them.
PngFormat CheckPngHeader(const std::string& path, const Camera& camera) {
  std::ifstream file(path, std::ios::binary);
  unsigned char header[26] = {};
  file.read(reinterpret_cast<char*>(header), sizeof(header));
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!file || !std::equal(kSignature, kSignature + 8, header) ||
      !std::equal(header + 12, header + 16, reinterpret_cast<const unsigned char*>("IHDR")))
    ThrowError(path, "", "unreadable image: expected a PNG file (bad or truncated PNG header)");
  auto big_endian = [&](int offset) {
    return (std::uint32_t{header[offset]} << 24) | (std::uint32_t{header[offset + 1]} << 16) |
           (std::uint32_t{header[offset + 2]} << 8) | std::uint32_t{header[offset + 3]};
  };
  const std::uint32_t width = big_endian(16), height = big_endian(20);
  if (width != static_cast<std::uint32_t>(camera.width()) ||
      height != static_cast<std::uint32_t>(camera.height()))
    ThrowError(path, "size",
               "expected " + SizeText(camera.width(), camera.height()) + " (camera \"" +
                   camera.name() + "\" in cameras.json), got " + std::to_string(width) + "×" +
                   std::to_string(height));
  return {header[24], header[25]};
}

// Warnings on the images' pixel formats (`formats`: per camera, the frames of each PNG
// format): every image is read as a gray intensity in [0, 1] (Dataset::Gray), which is
// right for any format, but a camera whose frames change format mid-take, cameras that
// differ, and 16-bit files (often 10- or 12-bit sensor data in the low bits, which then
// reads dark) are worth a line each.
std::vector<std::string> PixelFormatWarnings(const DatasetLayout& layout,
                                             const std::vector<std::map<PngFormat, std::vector<int>>>& formats) {
  std::vector<std::string> warnings;
  std::map<PngFormat, std::vector<std::string>> cameras_of;  // each camera by its first frame's format
  for (std::size_t c = 0; c < formats.size(); ++c) {
    if (formats[c].empty()) continue;
    const std::string& name = layout.cameras[c].name();
    if (formats[c].size() > 1) {
      std::string list;
      for (const auto& [format, frames] : formats[c])
        list += (list.empty() ? "" : ", ") + format.Text() + " in " + std::to_string(frames.size()) +
                (frames.size() == 1 ? " frame" : " frames") + " from " + FrameName(frames.front());
      warnings.push_back("camera \"" + name + "\": its images change pixel format within the take: " + list +
                         "; each is read as a gray intensity in [0, 1]");
    }
    PngFormat first;
    int first_frame = layout.frame_count;
    for (const auto& [format, frames] : formats[c])
      if (frames.front() < first_frame) first = format, first_frame = frames.front();
    cameras_of[first].push_back(name);
  }
  if (cameras_of.size() > 1) {
    std::string list;
    for (const auto& [format, names] : cameras_of)
      list += (list.empty() ? "" : "; ") + format.Text() + ": " + JoinedNames(names);
    warnings.push_back("cameras' images differ in pixel format (" + list +
                       "): each is read as a gray intensity in [0, 1] (8-bit / 255, 16-bit / 65535)");
  }
  std::vector<std::string> sixteen_bit;  // cameras with any 16-bit frame
  for (std::size_t c = 0; c < formats.size(); ++c)
    if (std::any_of(formats[c].begin(), formats[c].end(), [](const auto& entry) { return entry.first.bit_depth == 16; }))
      sixteen_bit.push_back(layout.cameras[c].name());
  if (!sixteen_bit.empty())
    warnings.push_back("16-bit images (camera" + std::string(sixteen_bit.size() > 1 ? "s " : " ") +
                       JoinedNames(sixteen_bit) +
                       ") are read as value / 65535: data of fewer bits in the low bits (10- or 12-bit sensors) "
                       "then reads dark, so scale such data to the full 16-bit range first");
  return warnings;
}

// The per-camera folders <root>/<camera>/ of <frame><extension> files (images/, masks/):
// returns each camera's frame indices; throws on unknown folders, stray files and
// cameras without a folder or without frames. With `extensions`, each camera's frames may
// use any one image extension of vision/import_media.h (docs/dataset.md), found from its
// first frame and returned per camera; without, `extension` is required.
std::vector<std::set<int>> ScanFrameFolders(const fs::path& root, const std::vector<Camera>& cameras,
                                            std::string extension,
                                            std::vector<std::string>* extensions = nullptr) {
  std::set<std::string> names;
  for (const Camera& camera : cameras) names.insert(camera.name());
  for (const auto& entry : fs::directory_iterator(root)) {
    if (Hidden(entry.path())) continue;
    if (!IsDirectory(entry.path()) || !names.count(entry.path().filename().string()))
      ThrowError(Str(entry.path()), "",
                 "unknown camera folder (expected one folder per camera of cameras.json: " +
                     CameraList(cameras) + ")");
  }
  std::vector<std::set<int>> frames(cameras.size());
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const fs::path folder = root / cameras[c].name();
    if (!IsDirectory(folder))
      ThrowError(Str(folder), "", "missing: camera \"" + cameras[c].name() +
                                      "\" has no folder (expected " + Str(folder) + "/000000" +
                                      extension + ", ...)");
    if (extensions) {
      extension = ".png";
      for (const auto& entry : fs::directory_iterator(folder)) {
        const std::string found = entry.path().extension().string();
        if (!Hidden(entry.path()) && IsImageExtension(found)) {
          extension = found;
          break;
        }
      }
      extensions->push_back(extension);
    }
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (Hidden(entry.path())) continue;
      const int frame = FrameIndex(entry.path().filename().string(), extension);
      if (frame < 0 || !IsFile(entry.path()))
        ThrowError(Str(entry.path()), "",
                   "unexpected file (expected frames named <6-digit frame>" + extension + ", e.g. 000000" +
                       extension + ")");
      frames[c].insert(frame);
    }
    if (frames[c].empty())
      ThrowError(Str(folder), "", "camera \"" + cameras[c].name() + "\" has no images (expected " +
                                      Str(folder / ("000000" + extension)) + ", ...)");
  }
  return frames;
}

// Every camera has exactly frames 0..frame_count-1.
void CheckFrames(const std::vector<std::set<int>>& frames, int frame_count, const fs::path& root,
                 const std::vector<Camera>& cameras, const std::string& extension,
                 const std::string& count_origin) {
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    for (int f = 0; f < frame_count; ++f)
      if (!frames[c].count(f))
        ThrowError(Str(root / cameras[c].name() / (FrameName(f) + extension)), "",
                   "missing frame " + std::to_string(f) + " of camera \"" + cameras[c].name() +
                       "\" (every camera must have frames 0.." + std::to_string(frame_count - 1) +
                       ", " + count_origin + ")");
    const int last = *frames[c].rbegin();
    if (last >= frame_count)
      ThrowError(Str(root / cameras[c].name() / (FrameName(last) + extension)), "",
                 "frame beyond frame_count " + std::to_string(frame_count) + " (" + count_origin + ")");
  }
}

}  // namespace

std::string DatasetLayout::ImagePath(int camera, int frame) const {
  if (videos) return video_paths[camera];
  const std::string extension = camera < static_cast<int>(image_extensions.size()) ? image_extensions[camera] : ".png";
  return Str(fs::path(directory) / "images" / cameras[camera].name() / (FrameName(frame) + extension));
}
std::string DatasetLayout::MaskPath(int camera, int frame) const {
  return Str(fs::path(directory) / "masks" / cameras[camera].name() / (FrameName(frame) + ".png"));
}
std::string DatasetLayout::BackgroundPath(int camera) const {
  return Str(fs::path(directory) / "background" / (cameras[camera].name() + ".png"));
}
std::string DatasetLayout::GroundTruthMeshPath(int frame) const {
  return Str(fs::path(directory) / "groundtruth" / "mesh" / (FrameName(frame) + ".ply"));
}

void DatasetLayout::CheckIndex(int camera, int frame) const {
  if (camera < 0 || camera >= static_cast<int>(cameras.size()))
    ThrowError(directory, "camera index", "expected 0.." + std::to_string(cameras.size() - 1) +
                                              ", got " + std::to_string(camera));
  if (frame < 0 || frame >= frame_count)
    ThrowError(directory, "frame index", "expected 0.." + std::to_string(frame_count - 1) +
                                             ", got " + std::to_string(frame));
}

void CheckImageSize(const cv::Mat& image, const Camera& camera, const std::string& what) {
  if (image.cols != camera.width() || image.rows != camera.height())
    ThrowError(what, "size",
               "expected " + SizeText(camera.width(), camera.height()) + " (camera \"" +
                   camera.name() + "\" in cameras.json), got " + SizeText(image.cols, image.rows));
}

cv::Mat ReadImageFile(const std::string& path, const Camera& camera) {
  if (!IsFile(path)) ThrowError(path, "", "missing image file");
  cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty())
    ThrowError(path, "", "unreadable image (cv::imread failed; expected an 8- or 16-bit PNG or another image file)");
  if ((image.depth() != CV_8U && image.depth() != CV_16U) ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    ThrowError(path, "pixel type",
               "expected 8- or 16-bit with 1, 3 or 4 channels, got depth " + std::to_string(image.depth()) +
                   " with " + std::to_string(image.channels()) + " channels");
  CheckImageSize(image, camera, path);
  return image;
}

namespace {

// The videos/<camera>.<ext> of a dataset: their paths, sizes and the frame count.
void ScanVideos(const fs::path& videos, DatasetLayout* out) {
  DatasetLayout& layout = *out;
  const std::vector<Camera>& cameras = layout.cameras;
  layout.videos = true;
  layout.video_paths.resize(cameras.size());
  for (const auto& entry : fs::directory_iterator(videos)) {
    if (Hidden(entry.path())) continue;
    const std::string stem = entry.path().stem().string();
    auto it = std::find_if(cameras.begin(), cameras.end(),
                           [&](const Camera& camera) { return camera.name() == stem; });
    if (it == cameras.end() || !IsFile(entry.path()))
      ThrowError(Str(entry.path()), "", "unknown camera video (expected videos/<camera>.<ext> for the "
                                        "cameras of cameras.json: " + CameraList(cameras) + ")");
    std::string& path = layout.video_paths[it - cameras.begin()];
    if (!path.empty())
      ThrowError(Str(entry.path()), "", "second video of camera \"" + stem + "\" (the first is " + path + ")");
    path = Str(entry.path());
  }
  std::map<int, std::string> counts;  // reported frame count → a video with it
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const std::string& path = layout.video_paths[c];
    if (path.empty())
      ThrowError(Str(videos / cameras[c].name()), "", "camera \"" + cameras[c].name() +
                                                          "\" has no video (expected videos/" +
                                                          cameras[c].name() + ".<ext>)");
    cv::VideoCapture capture(path);
    if (!capture.isOpened())
      ThrowError(path, "", "unreadable video (expected a file OpenCV's VideoCapture reads)");
    const int width = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_WIDTH));
    const int height = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_HEIGHT));
    if (width != cameras[c].width() || height != cameras[c].height())
      ThrowError(path, "size", "expected " + SizeText(cameras[c].width(), cameras[c].height()) +
                                   " (camera \"" + cameras[c].name() + "\" in cameras.json), got " +
                                   SizeText(width, height));
    const double reported = capture.get(cv::CAP_PROP_FRAME_COUNT);
    if (reported > kMaxFrameCount && !layout.info.frame_count)
      ThrowError(path, "frame count",
                 "the video reports " + std::to_string(reported) + " frames, more than " +
                     std::to_string(kMaxFrameCount) + "; give \"frame_count\" in cameras.json");
    // A count OpenCV cannot know comes as 0 or negative; beyond int it is no count.
    const int count = reported >= 1 && reported <= kMaxFrameCount ? static_cast<int>(reported) : 0;
    if (layout.info.frame_count) {
      if (count > 0 && count < *layout.info.frame_count)
        ThrowError(path, "frame count", "expected at least frame_count = " +
                                            std::to_string(*layout.info.frame_count) +
                                            " frames (cameras.json), the video has " + std::to_string(count));
    } else if (count <= 0) {
      ThrowError(path, "frame count", "unknown (the container does not report it); give "
                                      "\"frame_count\" in cameras.json");
    }
    counts[count] = path;
  }
  if (layout.info.frame_count) {
    layout.frame_count = *layout.info.frame_count;
  } else {
    if (counts.size() > 1)
      ThrowError(counts.rbegin()->second, "frame count",
                 "expected every video to have the same number of frames, got " +
                     std::to_string(counts.rbegin()->first) + " here and " +
                     std::to_string(counts.begin()->first) + " in " + counts.begin()->second);
    layout.frame_count = counts.begin()->first;
  }
}

DatasetLayout ScanLayout(const std::string& directory, bool check_image_headers) {
  DatasetLayout layout;
  layout.directory = directory;
  const fs::path root(directory);
  if (!IsDirectory(root))
    ThrowError(directory, "", "not a directory (expected a dataset directory with cameras.json)");
  layout.cameras_path = Str(root / "cameras.json");
  layout.cameras = ReadCamerasJson(layout.cameras_path, &layout.info);
  const std::vector<Camera>& cameras = layout.cameras;
  const std::string count_origin =
      layout.info.frame_count ? "frame_count in cameras.json" : "frame count found on disk";

  const fs::path images = root / "images", videos = root / "videos";
  if (EntryExists(images) && EntryExists(videos))
    ThrowError(directory, "images/ and videos/", "both present; expected exactly one source of frames");
  if (IsDirectory(images)) {
    const std::vector<std::set<int>> frames = ScanFrameFolders(images, cameras, ".png", &layout.image_extensions);
    if (layout.info.frame_count) {
      layout.frame_count = *layout.info.frame_count;
    } else {
      for (const auto& set : frames) layout.frame_count = std::max(layout.frame_count, *set.rbegin() + 1);
    }
    for (std::size_t c = 0; c < cameras.size(); ++c)
      CheckFrames({frames[c]}, layout.frame_count, images, {cameras[c]}, layout.image_extensions[c], count_origin);
  } else if (IsDirectory(videos)) {
    ScanVideos(videos, &layout);
  } else {
    ThrowError(directory, "images/", "missing (expected images/<camera>/<frame>.png or videos/<camera>.<ext>)");
  }

  const fs::path masks = root / "masks";
  if (EntryExists(masks)) {
    if (!IsDirectory(masks)) ThrowError(Str(masks), "", "expected a folder of per-camera mask folders");
    layout.masks = true;
    const std::vector<std::set<int>> frames = ScanFrameFolders(masks, cameras, ".png");
    CheckFrames(frames, layout.frame_count, masks, cameras, ".png",
                "the frame count of the dataset's images");
  }

  const fs::path background = root / "background";
  if (EntryExists(background)) {
    layout.background = true;
    std::set<std::string> names;
    for (const Camera& camera : cameras) names.insert(camera.name() + ".png");
    for (const auto& entry : fs::directory_iterator(background)) {
      if (Hidden(entry.path())) continue;
      if (!names.count(entry.path().filename().string()))
        ThrowError(Str(entry.path()), "", "unknown background image (expected background/<camera>.png "
                                          "for the cameras of cameras.json: " + CameraList(cameras) + ")");
    }
    for (int c = 0; c < static_cast<int>(cameras.size()); ++c)
      if (!IsFile(layout.BackgroundPath(c)))
        ThrowError(layout.BackgroundPath(c), "", "missing background image of camera \"" + cameras[c].name() +
                                                     "\" (background/ must have one per camera)");
  }

  const fs::path groundtruth = root / "groundtruth";
  if (EntryExists(groundtruth)) {
    const fs::path mesh = groundtruth / "mesh";
    if (!IsDirectory(mesh))
      ThrowError(Str(mesh), "", "missing (expected groundtruth/mesh/<frame>.ply)");
    layout.groundtruth = true;
    for (const auto& entry : fs::directory_iterator(mesh)) {
      if (Hidden(entry.path())) continue;
      const int frame = FrameIndex(entry.path().filename().string(), ".ply");
      if (frame < 0 || frame >= layout.frame_count)
        ThrowError(Str(entry.path()), "", "unexpected file (expected <frame>.ply for frames 000000.." +
                                              FrameName(layout.frame_count - 1) + ")");
    }
    for (int f = 0; f < layout.frame_count; ++f)
      if (!IsFile(layout.GroundTruthMeshPath(f)))
        ThrowError(layout.GroundTruthMeshPath(f), "", "missing ground-truth mesh of frame " + std::to_string(f));
  }

  if (check_image_headers) {
    std::vector<std::map<PngFormat, std::vector<int>>> formats(cameras.size());  // per camera: frames per format
    for (int c = 0; c < static_cast<int>(cameras.size()); ++c) {
      for (int f = 0; f < layout.frame_count; ++f) {
        if (!layout.videos && layout.image_extensions[c] == ".png")
          formats[c][CheckPngHeader(layout.ImagePath(c, f), cameras[c])].push_back(f);
        if (layout.masks) CheckPngHeader(layout.MaskPath(c, f), cameras[c]);
      }
      if (layout.background) CheckPngHeader(layout.BackgroundPath(c), cameras[c]);
    }
    layout.warnings = PixelFormatWarnings(layout, formats);
  }
  return layout;
}

}  // namespace

DatasetLayout ScanDatasetLayout(const std::string& directory, bool check_image_headers) {
  try {
    return ScanLayout(directory, check_image_headers);
  } catch (const fs::filesystem_error& e) {
    // Permissions, broken links and the like: still one line naming the path.
    ThrowError(e.path1().empty() ? directory : e.path1().string(), "", e.code().message());
  }
}

}  // namespace subflow::vision
