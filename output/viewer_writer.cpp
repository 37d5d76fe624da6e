#include "output/viewer_writer.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "output/base64.h"
#include "output/camera_texture.h"
#include "output/colour_scale.h"
#include "output/flow_magnitude.h"
#include "core/atomic_file.h"
#include "output/view_cameras.h"
#include "output/viewer_assets.h"

namespace subflow::output {
namespace {

template <typename T>
std::string Base64Of(const std::vector<T>& values) {
  return Base64(values.data(), values.size() * sizeof(T));
}

// Per-vertex sRGB bytes of one frame from the cameras that see each vertex best.
void AppendTexture(const vision::Dataset& dataset, const ResultFrame& frame, const geometry::Faces& F,
                   std::vector<std::uint8_t>* rgb) {
  const CameraTexture texture(dataset, frame.frame, frame.V, F);
  const geometry::Positions normals = geometry::VertexNormals(frame.V, F);
  for (Eigen::Index v = 0; v < frame.V.rows(); ++v) {
    Eigen::Vector3f colour(0.6f, 0.6f, 0.6f);  // gray where no camera sees the vertex
    texture.Colour(frame.V.row(v).transpose(), normals.row(v).transpose(), &colour);
    for (int c = 0; c < 3; ++c) rgb->push_back(static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(colour[c], 0.0f, 1.0f))));
  }
}

// The page: the template with the data and the bundle in place of their markers.
std::string Page(const nlohmann::json& data) {
  std::string page(ViewerTemplate());
  std::string bundle(ViewerBundle());
  for (std::size_t at = bundle.find("</script"); at != std::string::npos; at = bundle.find("</script", at))
    bundle.replace(at, 2, "<\\/");  // would end the inline script early
  const std::string data_marker = "/*SUBFLOW_DATA*/", bundle_marker = "/*SUBFLOW_BUNDLE*/";
  page.replace(page.find(data_marker), data_marker.size(), data.dump());
  page.replace(page.find(bundle_marker), bundle_marker.size(), bundle);
  return page;
}

}  // namespace

std::size_t EstimatedViewerBytes(std::size_t vertex_count, std::size_t frames, std::size_t magnitude_channels,
                                 bool texture) {
  // float32 x y z and one float32 per magnitude channel, 3 bytes of sRGB; base64 is 4/3.
  const std::size_t per_vertex = 12 + 4 * magnitude_channels + (texture ? 3 : 0);
  return frames * vertex_count * per_vertex / 3 * 4;
}

int ViewerStride(const ViewerOptions& options, std::size_t vertex_count, std::size_t frames,
                 std::size_t magnitude_channels, bool texture) {
  if (options.stride > 0) return options.stride;
  const std::size_t per_frame = std::max<std::size_t>(1, EstimatedViewerBytes(vertex_count, 1, magnitude_channels, texture));
  const std::size_t fitting = std::max<std::size_t>(1, options.max_bytes / per_frame);  // frames that fit
  return static_cast<int>((frames + fitting - 1) / fitting);
}

ViewerSummary WriteViewer(const ResultReader& result, const vision::Dataset* dataset, const ResultMetadata& metadata,
                          const std::string& path, const ViewerOptions& options, Progress* progress) {
  if (!ViewerAvailable())
    ThrowError(path, "", "this subflow was built without the viewer (viewer/node_modules was missing: run "
                         "scripts/install_deps.sh and rebuild)");
  std::vector<FlowKind> kinds = {FlowKind::kTotal};
  if (HasFlow(result, FlowKind::kNonRigid)) kinds.push_back(FlowKind::kNonRigid);
  std::vector<FlowRange> ranges;
  for (FlowKind kind : kinds) ranges.push_back(SequenceFlowRange(result, kind));
  const bool texture = options.texture && dataset;
  const auto vertex_count = static_cast<std::size_t>(result.vertex_count());
  const auto frame_count = static_cast<std::size_t>(result.frame_count());
  ViewerSummary summary;
  summary.stride = ViewerStride(options, vertex_count, frame_count, kinds.size(), texture);
  summary.estimated_bytes_all_frames = EstimatedViewerBytes(vertex_count, frame_count, kinds.size(), texture);

  std::vector<float> positions;
  std::vector<std::vector<float>> magnitudes(kinds.size());
  std::vector<std::uint8_t> rgb;
  nlohmann::json frame_names = nlohmann::json::array();
  ProgressBegin(progress, "viewer", frame_count);
  std::size_t visited = 0;
  ForEachFrameFlow(result, kinds, [&](const ResultFrame& frame, const std::vector<Eigen::VectorXf>& values) {
    ProgressUpdate(progress, ++visited);
    if ((visited - 1) % static_cast<std::size_t>(summary.stride) != 0) return;
    for (Eigen::Index k = 0; k < frame.V.size(); ++k) positions.push_back(static_cast<float>(frame.V.data()[k]));
    for (std::size_t k = 0; k < kinds.size(); ++k)
      magnitudes[k].insert(magnitudes[k].end(), values[k].data(), values[k].data() + values[k].size());
    if (texture) AppendTexture(*dataset, frame, result.faces(), &rgb);
    frame_names.push_back(vision::FrameName(frame.frame));
  });
  summary.frames_in_page = static_cast<int>(frame_names.size());
  ProgressEnd(progress);

  const std::vector<std::uint32_t> indices(result.faces().data(), result.faces().data() + result.faces().size());
  nlohmann::json table = nlohmann::json::array();
  for (const auto& entry : ColourScale::Table()) table.push_back({entry[0], entry[1], entry[2]});
  const Eigen::Vector3d up = dataset ? CamerasUp(dataset->cameras()) : Eigen::Vector3d::UnitZ();
  nlohmann::json data = {{"title", options.title},
                         {"vertex_count", result.vertex_count()},
                         {"frame_count", summary.frames_in_page},
                         {"frame_names", frame_names},
                         {"stride", summary.stride},
                         {"fps", metadata.fps / summary.stride},  // page frames per second of real time
                         {"up", {up.x(), up.y(), up.z()}},
                         {"positions", Base64Of(positions)},
                         {"indices", Base64Of(indices)},
                         {"colour_table", table},
                         {"colourings", nlohmann::json::object()}};
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    const std::string name = kinds[k] == FlowKind::kTotal ? "flow" : "nonrigid";
    data["colourings"][name] = {{"title", kinds[k] == FlowKind::kTotal ? "scene flow" : "non-rigid flow"},
                                {"label", FlowLabel(kinds[k])},
                                {"units", metadata.DisplayUnit() + "/frame"},
                                {"display_factor", metadata.DisplayFactor()},
                                {"min", ranges[k].min},
                                {"max", ranges[k].max},
                                {"magnitudes", Base64Of(magnitudes[k])}};
    summary.colourings.push_back(name);
  }
  if (texture) {
    data["colourings"]["texture"] = {{"title", "texture (cameras)"}, {"rgb", Base64Of(rgb)}};
    summary.colourings.push_back("texture");
  }
  const std::string page = Page(data);
  AtomicFile file(path);
  file.stream().write(page.data(), static_cast<std::streamsize>(page.size()));
  file.Commit();
  summary.bytes = page.size();
  return summary;
}

}  // namespace subflow::output
