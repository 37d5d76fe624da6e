#include "vision/dataset_writer.h"

#include <filesystem>
#include <string_view>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "geometry/mesh_io.h"

namespace subflow::vision {
namespace fs = std::filesystem;
namespace {

const char* const kDatasetEntries[] = {"cameras.json", "report.json", "preview", "images", "videos", "masks", "background",
                                       "groundtruth"};

void CreateDirectories(const fs::path& path) {
  std::error_code error;
  fs::create_directories(path, error);
  if (error) ThrowError(path.string(), "", "cannot create directory: " + error.message());
}

}  // namespace

void WritePng(const std::string& path, const cv::Mat& image) {
  ThrowIfInterrupted();  // between two files is a natural point to stop at (core/interrupt.h)
  CreateDirectories(fs::path(path).parent_path());
  std::vector<unsigned char> bytes;
  bool encoded = false;
  try {
    encoded = cv::imencode(".png", image, bytes, {cv::IMWRITE_PNG_COMPRESSION, 3});
  } catch (const cv::Exception& e) {
    ThrowError(path, "", std::string("cannot encode PNG: ") + e.what());
  }
  if (!encoded) ThrowError(path, "", "cannot encode PNG (cv::imencode failed)");
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void CheckDatasetDirectory(const std::string& directory, bool overwrite) {
  const fs::path root(directory);
  if (!fs::exists(root)) return;
  if (!fs::is_directory(root))
    ThrowError(directory, "", "exists and is not a directory (expected a new dataset directory)");
  if (!fs::is_empty(root) && !overwrite)
    ThrowError(directory, "", "exists and is not empty; refusing to overwrite it (choose another directory or pass "
                               "--overwrite to replace the dataset in it)");
}

void PrepareDatasetDirectory(const std::string& directory, bool overwrite) {
  CheckDatasetDirectory(directory, overwrite);
  const fs::path root(directory);
  if (fs::exists(root)) {
    if (!fs::is_empty(root)) {
      for (const char* entry : kDatasetEntries) {
        std::error_code error;
        fs::remove_all(root / entry, error);
        if (error) ThrowError((root / entry).string(), "", "cannot remove: " + error.message());
      }
    }
  }
  CreateDirectories(root);
}

DatasetWriter::DatasetWriter(const std::string& directory, std::vector<Camera> cameras,
                             const DatasetInfo& info, bool overwrite)
    : directory_(directory), cameras_(std::move(cameras)), info_(info) {
  PrepareDatasetDirectory(directory_, overwrite);
  const fs::path root(directory_);
  WriteCamerasJson((root / "cameras.json").string(), cameras_, info_.fps, info_.frame_count,
                   info_.bounds, info_.units);
  for (const Camera& camera : cameras_) CreateDirectories(root / "images" / camera.name());
}

void DatasetWriter::CheckImage(int camera, const cv::Mat& image, const std::string& path) const {
  if (camera < 0 || camera >= static_cast<int>(cameras_.size()))
    ThrowError(path, "camera index", "expected 0.." + std::to_string(cameras_.size() - 1) + ", got " +
                                         std::to_string(camera));
  const Camera& c = cameras_[camera];
  if (image.cols != c.width() || image.rows != c.height())
    ThrowError(path, "size", "expected " + std::to_string(c.width()) + "×" + std::to_string(c.height()) +
                                 " (camera \"" + c.name() + "\"), got " + std::to_string(image.cols) + "×" +
                                 std::to_string(image.rows));
  if ((image.depth() != CV_8U && image.depth() != CV_16U) ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    ThrowError(path, "pixel type", "expected 8- or 16-bit with 1, 3 or 4 channels");
}

void DatasetWriter::WriteImage(int camera, int frame, const cv::Mat& image) const {
  if (frame < 0 || (info_.frame_count && frame >= *info_.frame_count))
    ThrowError(directory_, "frame index", "out of range: " + std::to_string(frame));
  if (camera < 0 || camera >= static_cast<int>(cameras_.size())) CheckImage(camera, image, directory_);
  const fs::path path = fs::path(directory_) / "images" / cameras_[camera].name() / (FrameName(frame) + ".png");
  CheckImage(camera, image, path.string());
  WritePng(path.string(), image);
}

void DatasetWriter::WriteMask(int camera, int frame, const cv::Mat& mask) const {
  if (frame < 0 || (info_.frame_count && frame >= *info_.frame_count))
    ThrowError(directory_, "frame index", "out of range: " + std::to_string(frame));
  if (camera < 0 || camera >= static_cast<int>(cameras_.size())) CheckImage(camera, mask, directory_);
  const fs::path path = fs::path(directory_) / "masks" / cameras_[camera].name() / (FrameName(frame) + ".png");
  CheckImage(camera, mask, path.string());
  if (mask.type() != CV_8UC1) ThrowError(path.string(), "pixel type", "expected a CV_8UC1 mask");
  cv::Mat binary = mask != 0;
  WritePng(path.string(), binary);
}

void DatasetWriter::WriteBackground(int camera, const cv::Mat& image) const {
  if (camera < 0 || camera >= static_cast<int>(cameras_.size())) CheckImage(camera, image, directory_);
  const fs::path path = fs::path(directory_) / "background" / (cameras_[camera].name() + ".png");
  CheckImage(camera, image, path.string());
  WritePng(path.string(), image);
}

void DatasetWriter::WriteGroundTruthMesh(int frame, const geometry::TriangleMesh& mesh) const {
  if (frame < 0 || (info_.frame_count && frame >= *info_.frame_count))
    ThrowError(directory_, "frame index", "out of range: " + std::to_string(frame));
  const fs::path path = fs::path(directory_) / "groundtruth" / "mesh" / (FrameName(frame) + ".ply");
  CreateDirectories(path.parent_path());
  geometry::WriteMesh(path.string(), mesh);
}

}  // namespace subflow::vision
