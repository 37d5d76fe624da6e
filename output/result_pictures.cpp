#include "output/result_pictures.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "output/camera_texture.h"
#include "output/flow_magnitude.h"
#include "vision/dataset_writer.h"

namespace subflow::output {
namespace {

namespace fs = std::filesystem;

Eigen::MatrixX3f VertexColours(const Eigen::VectorXf& magnitudes, const ColourScale& scale) {
  Eigen::MatrixX3f colours(magnitudes.size(), 3);
  for (Eigen::Index v = 0; v < magnitudes.size(); ++v) colours.row(v) = scale.Srgb(magnitudes[v]).transpose();
  return colours;
}

// The frames to picture: the given ones (checked), or first, middle and last.
std::vector<int> SelectedFrames(const ResultReader& result, const std::vector<int>& frames) {
  const int first = result.first_frame(), last = first + result.frame_count() - 1;
  if (frames.empty()) {
    const std::set<int> defaults = {first, first + (last - first) / 2, last};
    return {defaults.begin(), defaults.end()};
  }
  for (int frame : frames)
    if (frame < first || frame > last)
      ThrowError("--frames", "frame " + std::to_string(frame),
                 "not in the result (frames " + std::to_string(first) + " to " + std::to_string(last) + ")");
  return frames;
}

class PictureWriter {
 public:
  PictureWriter(const std::string& out, RenderSummary* summary) : out_(out), summary_(summary) {}

  // Writes `picture` (with the bar of `scale` when given) at <out>/<relative>.
  void Write(const std::string& relative, const cv::Mat& picture, const vision::ZBuffer& zbuffer,
             const std::string& kind, int frame, const std::string& view, const ColourScale* scale) {
    Picture entry;
    entry.path = relative;
    entry.kind = kind;
    entry.frame = frame;
    entry.view = view;
    entry.surface_pixels = zbuffer.CoveredPixelCount();
    entry.pixels = zbuffer.width() * zbuffer.height();
    cv::Mat written = picture;
    if (scale) {
      written = WithColourBar(picture, *scale, &entry.bar);
      entry.has_bar = true;
    }
    vision::WritePng((fs::path(out_) / relative).string(), written);
    summary_->pictures.push_back(entry);
  }

 private:
  std::string out_;
  RenderSummary* summary_;
};

}  // namespace

nlohmann::json RenderSummary::Json() const {
  nlohmann::json json = {{"pictures", nlohmann::json::array()}, {"colour_scales", nlohmann::json::object()}};
  for (const Picture& p : pictures) {
    nlohmann::json entry = {{"path", p.path}, {"kind", p.kind}, {"frame", p.frame}, {"view", p.view},
                            {"surface_pixels", p.surface_pixels}, {"pixels", p.pixels}};
    if (p.has_bar) entry["colour_bar"] = {{"left", p.bar.left}, {"right", p.bar.right}, {"top", p.bar.top},
                                          {"bottom", p.bar.bottom}};
    json["pictures"].push_back(entry);
  }
  for (const auto& [name, s] : scales)
    json["colour_scales"][name] = {{"min", s.min}, {"max", s.max}, {"display_factor", s.display_factor},
                                   {"label", s.label}, {"units", s.units}};
  return json;
}

namespace {

// One MP4 per camera, written under a temporary name and renamed when complete.
class Mp4Writers {
 public:
  Mp4Writers(const std::string& out, double fps) : directory_(fs::path(out) / "mp4"), fps_(fps) {}

  void Write(const std::string& camera, const cv::Mat& picture) {
    cv::Mat even;  // codecs want even sizes
    cv::copyMakeBorder(picture, even, 0, picture.rows % 2, 0, picture.cols % 2, cv::BORDER_REPLICATE);
    Video& video = videos_[camera];
    if (!video.writer.isOpened()) {
      fs::create_directories(directory_);
      video.file = std::make_unique<AtomicFile>((directory_ / (camera + ".mp4")).string(), AtomicFile::kKeepExtension);
      video.writer.open(video.file->temporary(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps_, even.size());
      if (!video.writer.isOpened())
        ThrowError(video.file->path(), "", "OpenCV cannot write MP4 (mp4v) on this system");
    }
    video.writer.write(even);
  }

  // Closes and renames every video; adds them to `summary`.
  void Finish(int first_frame, RenderSummary* summary) {
    for (auto& [camera, video] : videos_) {
      video.writer.release();
      video.file->Commit();
      summary->pictures.push_back({"mp4/" + camera + ".mp4", "mp4", first_frame, camera, 0, 0, {}, false});
    }
  }

 private:
  fs::path directory_;
  double fps_;
  struct Video {
    std::unique_ptr<AtomicFile> file;  // the temporary is removed unless committed
    cv::VideoWriter writer;
  };
  std::map<std::string, Video> videos_;
};

// What every picture of one frame shares.
struct FrameScene {
  const ResultFrame& frame;
  const geometry::Faces& F;
  geometry::Positions normals;
  std::vector<Eigen::MatrixX3f> colours;  // per flow kind
  std::string name;                       // six-digit frame name
  bool selected;                          // picture it (else only the MP4)
};

class ResultPainter {
 public:
  ResultPainter(const vision::Dataset* dataset, const std::vector<std::string>& kinds,
                const std::vector<ColourScale>& scales, const RenderOptions& options, const std::string& out,
                double fps, RenderSummary* summary)
      : dataset_(dataset), kinds_(kinds), scales_(scales), options_(options), writer_(out, summary), mp4_(out, fps) {}

  // Flow pictures, overlays and the contact sheet from the dataset's cameras.
  void CameraPictures(const FrameScene& scene) {
    const std::vector<vision::ZBuffer> zbuffers = vision::RenderZBuffers(dataset_->cameras(), scene.frame.V, scene.F);
    std::vector<cv::Mat> sheet;
    std::vector<std::string> labels;
    for (int c = 0; c < dataset_->camera_count(); ++c) {
      const vision::ZBuffer& zbuffer = zbuffers[static_cast<std::size_t>(c)];
      const std::string camera = dataset_->camera(c).name();
      std::vector<cv::Mat> shaded;
      for (std::size_t k = 0; k < kinds_.size(); ++k) {
        shaded.push_back(ShadeVertexColours(zbuffer, scene.frame.V, scene.F, scene.normals, scene.colours[k], options_.shading));
        if (scene.selected)
          writer_.Write(kinds_[k] + "/" + camera + "/" + scene.name + ".png", shaded[k], zbuffer, kinds_[k],
                        scene.frame.frame, camera, &scales_[k]);
      }
      if (!options_.overlays && !options_.mp4) continue;
      const cv::Mat image = dataset_->camera(c).UndistortImage(ToBgr8(dataset_->Image(c, scene.frame.frame)));
      const cv::Mat overlay = Overlay(image, shaded[0], zbuffer.Mask(), SurfaceOutline(zbuffer), options_.overlay);
      if (scene.selected && options_.overlays) {
        writer_.Write("overlay/" + camera + "/" + scene.name + ".png", overlay, zbuffer, "overlay", scene.frame.frame,
                      camera, &scales_[0]);
        sheet.push_back(overlay);
        labels.push_back(camera + " " + scene.name);
      }
      if (options_.mp4) mp4_.Write(camera, WithColourBar(overlay, scales_[0]));
    }
    if (sheet.empty()) return;
    const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(sheet.size()))));
    writer_.Write("contact_sheet/" + scene.name + ".png", ContactSheet(sheet, labels, columns, std::min(480, sheet[0].cols)),
                  zbuffers.front(), "contact_sheet", scene.frame.frame, "all", nullptr);
  }

  // Flow pictures and textured pictures from new views around the object.
  void TurntablePictures(const FrameScene& scene, const Eigen::Vector3d& up) {
    std::unique_ptr<CameraTexture> texture;
    if (dataset_ && options_.textured)
      texture = std::make_unique<CameraTexture>(*dataset_, scene.frame.frame, scene.frame.V, scene.F);
    ShadingOptions unlit = options_.shading;  // the images carry their own light
    unlit.ambient = 1.0;
    for (const vision::Camera& view : TurntableCameras(scene.frame.V, up, options_.turntable)) {
      const vision::ZBuffer zbuffer(view, scene.frame.V, scene.F);
      for (std::size_t k = 0; k < kinds_.size(); ++k)
        writer_.Write("turntable/" + kinds_[k] + "_" + scene.name + "_" + view.name() + ".png",
                      ShadeVertexColours(zbuffer, scene.frame.V, scene.F, scene.normals, scene.colours[k], options_.shading),
                      zbuffer, kinds_[k], scene.frame.frame, view.name(), &scales_[k]);
      if (!texture) continue;
      const PixelColour colour = [&](int, int, const Eigen::Vector3d& X, const Eigen::Vector3d& n) {
        Eigen::Vector3f rgb(0.6f, 0.6f, 0.6f);  // gray where no camera sees the point
        texture->Colour(X, n, &rgb);
        return rgb;
      };
      writer_.Write("textured/" + scene.name + "_" + view.name() + ".png",
                    ShadePixelColours(zbuffer, scene.frame.V, scene.F, scene.normals, colour, unlit), zbuffer, "textured",
                    scene.frame.frame, view.name(), nullptr);
    }
  }

  void Finish(int first_frame, RenderSummary* summary) { mp4_.Finish(first_frame, summary); }

 private:
  const vision::Dataset* dataset_;
  const std::vector<std::string>& kinds_;
  const std::vector<ColourScale>& scales_;
  const RenderOptions& options_;
  PictureWriter writer_;
  Mp4Writers mp4_;
};

}  // namespace

RenderSummary RenderResultPictures(const ResultReader& result, const vision::Dataset* dataset,
                                   const ResultMetadata& metadata, const std::string& out,
                                   const RenderOptions& options, Progress* progress) {
  if (dataset && dataset->frame_count() < result.first_frame() + result.frame_count())
    ThrowError(dataset->directory(), "frames", "the dataset has fewer frames than the result");
  RenderSummary summary;
  std::vector<FlowKind> kinds = {FlowKind::kTotal};
  if (HasFlow(result, FlowKind::kNonRigid)) kinds.push_back(FlowKind::kNonRigid);
  if (!options.colour_by.empty()) kinds.clear();
  std::vector<std::string> kind_names;
  std::vector<ColourScale> scales;
  for (FlowKind kind : kinds) {
    const FlowRange range = SequenceFlowRange(result, kind);
    kind_names.push_back(kind == FlowKind::kTotal ? "flow" : "nonrigid");
    scales.push_back({range.min, range.max, metadata.DisplayFactor(), FlowLabel(kind), metadata.DisplayUnit() + "/frame"});
  }
  if (!options.colour_by.empty()) {
    FlowRange range{options.colour_range.empty() ? 0.0 : options.colour_range[0],
                    options.colour_range.empty() ? 0.0 : options.colour_range[1]};
    if (options.colour_range.empty()) {
      range = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
      ForEachFrameProperty(result, options.colour_by, [&](const ResultFrame&, const Eigen::VectorXf& values) {
        range.min = std::min(range.min, static_cast<double>(values.minCoeff()));
        range.max = std::max(range.max, static_cast<double>(values.maxCoeff()));
      });
    } else if (options.colour_range.size() != 2 || !(options.colour_range[0] < options.colour_range[1])) {
      ThrowError("--colour-range", "", "expected MIN,MAX with MIN < MAX");
    }
    kind_names.push_back(options.colour_by);
    scales.push_back({range.min, range.max, metadata.DisplayFactor(), options.colour_by, metadata.DisplayUnit()});
  }
  for (std::size_t k = 0; k < kind_names.size(); ++k) summary.scales[kind_names[k]] = scales[k];
  const std::vector<int> frames = SelectedFrames(result, options.frames);
  const int turntable_frame = options.turntable_frame >= 0 ? options.turntable_frame
                                                           : result.first_frame() + (result.frame_count() - 1) / 2;
  SelectedFrames(result, {turntable_frame});
  const Eigen::Vector3d up = dataset ? CamerasUp(dataset->cameras()) : Eigen::Vector3d::UnitZ();
  ResultPainter painter(dataset, kind_names, scales, options, out, metadata.fps, &summary);

  ProgressBegin(progress, "pictures", static_cast<std::size_t>(result.frame_count()));
  const auto paint = [&](const ResultFrame& frame, const std::vector<Eigen::VectorXf>& magnitudes) {
    const bool selected = std::find(frames.begin(), frames.end(), frame.frame) != frames.end();
    const bool turntable = frame.frame == turntable_frame && options.turntable.count > 0;
    if (selected || turntable || (options.mp4 && dataset)) {
      FrameScene scene{frame, result.faces(), geometry::VertexNormals(frame.V, result.faces()), {},
                       vision::FrameName(frame.frame), selected};
      for (std::size_t k = 0; k < scales.size(); ++k) scene.colours.push_back(VertexColours(magnitudes[k], scales[k]));
      if (dataset) painter.CameraPictures(scene);
      if (turntable) painter.TurntablePictures(scene, up);
    }
    ProgressUpdate(progress, static_cast<std::size_t>(frame.frame - result.first_frame() + 1));
  };
  if (options.colour_by.empty())
    ForEachFrameFlow(result, kinds, paint);
  else
    ForEachFrameProperty(result, options.colour_by,
                         [&](const ResultFrame& frame, const Eigen::VectorXf& values) { paint(frame, {values}); });
  ProgressEnd(progress);
  painter.Finish(result.first_frame(), &summary);
  return summary;
}

}  // namespace subflow::output
