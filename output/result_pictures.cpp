#include "output/result_pictures.h"

#include <filesystem>
#include <set>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "output/camera_texture.h"
#include "output/flow_magnitude.h"
#include "output/output_file.h"

namespace subflow::output {
namespace {

namespace fs = std::filesystem;

void WritePng(const fs::path& path, const cv::Mat& picture) {
  fs::create_directories(path.parent_path());
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", picture, bytes)) ThrowError(path.string(), "", "OpenCV cannot encode the PNG");
  OutputFile file(path.string());
  file.stream().write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  file.Commit();
}

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
    Picture entry{relative, kind, frame, view, zbuffer.CoveredPixelCount(), zbuffer.width() * zbuffer.height()};
    cv::Mat written = picture;
    if (scale) {
      written = WithColourBar(picture, *scale, &entry.bar);
      entry.has_bar = true;
    }
    WritePng(fs::path(out_) / relative, written);
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

RenderSummary RenderResultPictures(const ResultReader& result, const vision::Dataset* dataset,
                                   const ResultMetadata& metadata, const std::string& out,
                                   const RenderOptions& options, Progress* progress) {
  RenderSummary summary;
  PictureWriter writer(out, &summary);
  if (dataset && dataset->frame_count() < result.first_frame() + result.frame_count())
    ThrowError(dataset->directory(), "frames", "the dataset has fewer frames than the result");
  std::vector<FlowKind> kinds = {FlowKind::kTotal};
  if (HasFlow(result, FlowKind::kNonRigid)) kinds.push_back(FlowKind::kNonRigid);
  std::vector<ColourScale> scales;
  for (FlowKind kind : kinds) {
    const FlowRange range = SequenceFlowRange(result, kind);
    ColourScale scale{range.min, range.max, metadata.DisplayFactor(), FlowLabel(kind), metadata.DisplayUnit() + "/frame"};
    scales.push_back(scale);
    summary.scales[kind == FlowKind::kTotal ? "flow" : "nonrigid"] = scale;
  }
  const std::vector<int> frames = SelectedFrames(result, options.frames);
  const int turntable_frame = options.turntable_frame >= 0 ? options.turntable_frame
                                                           : result.first_frame() + (result.frame_count() - 1) / 2;
  SelectedFrames(result, {turntable_frame});
  const Eigen::Vector3d up = dataset ? CamerasUp(dataset->cameras()) : Eigen::Vector3d::UnitZ();
  const bool images = dataset && (options.overlays || options.textured || options.mp4);
  std::map<int, cv::VideoWriter> videos;
  std::map<int, fs::path> video_paths;

  ProgressBegin(progress, "pictures", static_cast<std::size_t>(result.frame_count()));
  ForEachFrameFlow(result, kinds, [&](const ResultFrame& frame, const std::vector<Eigen::VectorXf>& magnitudes) {
    const bool selected = std::find(frames.begin(), frames.end(), frame.frame) != frames.end();
    const bool turntable = frame.frame == turntable_frame && options.turntable.count > 0;
    ProgressUpdate(progress, static_cast<std::size_t>(frame.frame - result.first_frame() + 1));
    if (!selected && !turntable && !options.mp4) return;
    const geometry::Faces& F = result.faces();
    const geometry::Positions normals = geometry::VertexNormals(frame.V, F);
    const std::string name = vision::FrameName(frame.frame);
    std::vector<Eigen::MatrixX3f> colours;
    for (std::size_t k = 0; k < kinds.size(); ++k) colours.push_back(VertexColours(magnitudes[k], scales[k]));

    if (dataset) {
      const std::vector<vision::ZBuffer> zbuffers = vision::RenderZBuffers(dataset->cameras(), frame.V, F);
      std::vector<cv::Mat> sheet;
      std::vector<std::string> labels;
      for (int c = 0; c < dataset->camera_count(); ++c) {
        const vision::ZBuffer& zbuffer = zbuffers[static_cast<std::size_t>(c)];
        const std::string camera = dataset->camera(c).name();
        std::vector<cv::Mat> shaded;
        for (std::size_t k = 0; k < kinds.size(); ++k) {
          shaded.push_back(ShadeVertexColours(zbuffer, frame.V, F, normals, colours[k], options.shading));
          const std::string kind = k == 0 ? "flow" : "nonrigid";
          if (selected) writer.Write(kind + "/" + camera + "/" + name + ".png", shaded[k], zbuffer, kind, frame.frame, camera, &scales[k]);
        }
        if (!images || !(options.overlays || options.mp4)) continue;
        const cv::Mat image = dataset->camera(c).UndistortImage(ToBgr8(dataset->Image(c, frame.frame)));
        const cv::Mat overlay = Overlay(image, shaded[0], zbuffer.Mask(), SurfaceOutline(zbuffer), options.overlay);
        if (selected && options.overlays) {
          writer.Write("overlay/" + camera + "/" + name + ".png", overlay, zbuffer, "overlay", frame.frame, camera, &scales[0]);
          sheet.push_back(overlay);
          labels.push_back(camera + " " + name);
        }
        if (options.mp4) {
          const cv::Mat picture = WithColourBar(overlay, scales[0]);
          cv::Mat even;  // codecs want even sizes
          cv::copyMakeBorder(picture, even, 0, picture.rows % 2, 0, picture.cols % 2, cv::BORDER_REPLICATE);
          if (!videos.count(c)) {
            video_paths[c] = fs::path(out) / "mp4" / (camera + ".partial.mp4");
            fs::create_directories(video_paths[c].parent_path());
            videos[c].open(video_paths[c].string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'), metadata.fps, even.size());
            if (!videos[c].isOpened())
              ThrowError(video_paths[c].string(), "", "OpenCV cannot write MP4 (mp4v) on this system");
          }
          videos[c].write(even);
        }
      }
      if (!sheet.empty()) {
        const vision::ZBuffer& zbuffer = zbuffers.front();
        const int columns = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(sheet.size()))));
        writer.Write("contact_sheet/" + name + ".png", ContactSheet(sheet, labels, columns, std::min(480, sheet[0].cols)),
                     zbuffer, "contact_sheet", frame.frame, "all", nullptr);
      }
    }
    if (!turntable) return;
    const std::vector<vision::Camera> views = TurntableCameras(frame.V, up, options.turntable);
    std::unique_ptr<CameraTexture> texture;
    if (images && options.textured) texture = std::make_unique<CameraTexture>(*dataset, frame.frame, frame.V, F);
    for (const vision::Camera& view : views) {
      const vision::ZBuffer zbuffer(view, frame.V, F);
      for (std::size_t k = 0; k < kinds.size(); ++k) {
        const std::string kind = k == 0 ? "flow" : "nonrigid";
        writer.Write("turntable/" + kind + "_" + name + "_" + view.name() + ".png",
                     ShadeVertexColours(zbuffer, frame.V, F, normals, colours[k], options.shading), zbuffer, kind,
                     frame.frame, view.name(), &scales[k]);
      }
      if (!texture) continue;
      const cv::Mat textured = ShadePixelColours(
          zbuffer, frame.V, F, normals,
          [&](int, int, const Eigen::Vector3d& X, const Eigen::Vector3d& n) {
            Eigen::Vector3f rgb(0.6f, 0.6f, 0.6f);  // gray where no camera sees the point
            texture->Colour(X, n, &rgb);
            return rgb;
          },
          [&] { ShadingOptions flat = options.shading; flat.ambient = 1.0; return flat; }());
      writer.Write("textured/" + name + "_" + view.name() + ".png", textured, zbuffer, "textured", frame.frame,
                   view.name(), nullptr);
    }
  });
  ProgressEnd(progress);
  for (auto& [c, video] : videos) {
    video.release();
    const fs::path final_path = fs::path(out) / "mp4" / (dataset->camera(c).name() + ".mp4");
    fs::rename(video_paths[c], final_path);
    summary.pictures.push_back({fs::relative(final_path, out).string(), "mp4", result.first_frame(),
                                dataset->camera(c).name(), 0, 0, {}, false});
  }
  return summary;
}

}  // namespace subflow::output
