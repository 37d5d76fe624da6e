#include "output/glb_writer.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <tiny_gltf.h>

#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "core/atomic_file.h"
#include "vision/dataset.h"

namespace subflow::output {
namespace {

using Floats = std::vector<float>;  // #V×3 row-major attribute values

// Buffer views and accessors appended to one buffer.
class GltfBuilder {
 public:
  GltfBuilder() { model_.buffers.emplace_back(); }
  tinygltf::Model& model() { return model_; }

  int AddView(const void* data, std::size_t bytes, int target = 0) {
    std::vector<unsigned char>& buffer = model_.buffers[0].data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* begin = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), begin, begin + bytes);
    model_.bufferViews.push_back(view);
    return static_cast<int>(model_.bufferViews.size()) - 1;
  }

  int AddAccessor(int view, int component_type, std::size_t count, int type,
                  std::vector<double> min = {}, std::vector<double> max = {}) {
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.byteOffset = 0;
    accessor.componentType = component_type;
    accessor.count = count;
    accessor.type = type;
    accessor.minValues = std::move(min);
    accessor.maxValues = std::move(max);
    accessor.sparse.isSparse = false;
    model_.accessors.push_back(accessor);
    return static_cast<int>(model_.accessors.size()) - 1;
  }

  // A VEC3 float accessor of `values` (#V×3), with min/max when asked.
  int AddVec3(const Floats& values, bool bounds) {
    const std::size_t count = values.size() / 3;
    const int view = AddView(values.data(), values.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
    std::vector<double> min, max;
    if (bounds) Bounds(values, {}, &min, &max);
    return AddAccessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, count, TINYGLTF_TYPE_VEC3, min, max);
  }

  // A morph-target delta accessor: sparse (only the rows that are not zero, on an
  // implicit all-zero accessor) when allowed and smaller, dense otherwise.
  int AddDelta(const Floats& deltas, bool allow_sparse, bool bounds, bool* stored_sparse) {
    const std::size_t count = deltas.size() / 3;
    std::vector<std::uint32_t> rows;
    for (std::size_t v = 0; v < count; ++v)
      if (deltas[3 * v] != 0.0f || deltas[3 * v + 1] != 0.0f || deltas[3 * v + 2] != 0.0f)
        rows.push_back(static_cast<std::uint32_t>(v));
    const bool small_indices = count <= std::numeric_limits<std::uint16_t>::max();
    const std::size_t sparse_bytes = rows.size() * (12 + (small_indices ? 2 : 4));
    *stored_sparse = allow_sparse && !rows.empty() && sparse_bytes < deltas.size() * sizeof(float);
    if (!*stored_sparse) return AddVec3(deltas, bounds);
    Floats values;
    values.reserve(rows.size() * 3);
    for (std::uint32_t v : rows) values.insert(values.end(), &deltas[3 * v], &deltas[3 * v] + 3);
    int index_view;
    if (small_indices) {
      std::vector<std::uint16_t> indices(rows.begin(), rows.end());
      index_view = AddView(indices.data(), indices.size() * 2);
    } else {
      index_view = AddView(rows.data(), rows.size() * 4);
    }
    const int value_view = AddView(values.data(), values.size() * sizeof(float));
    std::vector<double> min, max;
    if (bounds) Bounds(values, rows.size() < count ? std::vector<double>{0, 0, 0} : std::vector<double>{}, &min, &max);
    const int accessor = AddAccessor(-1, TINYGLTF_COMPONENT_TYPE_FLOAT, count, TINYGLTF_TYPE_VEC3, min, max);
    tinygltf::Accessor& sparse = model_.accessors[static_cast<std::size_t>(accessor)];
    sparse.sparse.isSparse = true;
    sparse.sparse.count = static_cast<int>(rows.size());
    sparse.sparse.indices.bufferView = index_view;
    sparse.sparse.indices.byteOffset = 0;
    sparse.sparse.indices.componentType =
        small_indices ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    sparse.sparse.values.bufferView = value_view;
    sparse.sparse.values.byteOffset = 0;
    return accessor;
  }

 private:
  // Component-wise min/max of the rows of `values` (and of `extra` when given).
  static void Bounds(const Floats& values, const std::vector<double>& extra, std::vector<double>* min,
                     std::vector<double>* max) {
    *min = std::vector<double>(3, std::numeric_limits<double>::infinity());
    *max = std::vector<double>(3, -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      (*min)[i % 3] = std::min((*min)[i % 3], static_cast<double>(values[i]));
      (*max)[i % 3] = std::max((*max)[i % 3], static_cast<double>(values[i]));
    }
    for (std::size_t k = 0; k < extra.size(); ++k) {
      (*min)[k] = std::min((*min)[k], extra[k]);
      (*max)[k] = std::max((*max)[k], extra[k]);
    }
  }

  tinygltf::Model model_;
};

Floats ToFloats(const geometry::Positions& V) {
  Floats values(static_cast<std::size_t>(V.size()));
  for (Eigen::Index k = 0; k < V.size(); ++k) values[static_cast<std::size_t>(k)] = static_cast<float>(V.data()[k]);
  return values;
}

// Unit vertex normals; a vertex with no non-degenerate face gets +Y (glTF wants unit normals).
Floats UnitNormals(const geometry::Positions& V, const geometry::Faces& F) {
  geometry::Positions N = geometry::VertexNormals(V, F);
  for (Eigen::Index v = 0; v < N.rows(); ++v)
    if (!(N.row(v).squaredNorm() > 0.5)) N.row(v) << 0.0, 1.0, 0.0;
  return ToFloats(N);
}

Floats LinearColours(const Eigen::VectorXf& magnitudes, const ColourScale& scale) {
  Floats colours(static_cast<std::size_t>(magnitudes.size()) * 3);
  for (Eigen::Index v = 0; v < magnitudes.size(); ++v) {
    const Eigen::Vector3f srgb = scale.Srgb(magnitudes[v]);
    for (int c = 0; c < 3; ++c) colours[static_cast<std::size_t>(3 * v + c)] = SrgbToLinear(srgb[c]);
  }
  return colours;
}

// (value − base) per component, in float.
Floats Delta(const Floats& value, const Floats& base) {
  Floats delta(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) delta[i] = value[i] - base[i];
  return delta;
}

// Position deltas computed in double from the float base, so base + delta rounds to the frame.
Floats PositionDelta(const geometry::Positions& V, const Floats& base) {
  Floats delta(base.size());
  for (std::size_t i = 0; i < base.size(); ++i)
    delta[i] = static_cast<float>(V.data()[i] - static_cast<double>(base[i]));
  return delta;
}

int AddIndices(GltfBuilder& builder, const geometry::Faces& F, int vertex_count) {
  const std::size_t count = static_cast<std::size_t>(F.size());
  if (vertex_count <= std::numeric_limits<std::uint16_t>::max()) {
    std::vector<std::uint16_t> indices(F.data(), F.data() + F.size());
    const int view = builder.AddView(indices.data(), count * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    return builder.AddAccessor(view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, count, TINYGLTF_TYPE_SCALAR);
  }
  std::vector<std::uint32_t> indices(F.data(), F.data() + F.size());
  const int view = builder.AddView(indices.data(), count * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  return builder.AddAccessor(view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, count, TINYGLTF_TYPE_SCALAR);
}

void AddAnimation(GltfBuilder& builder, int frame_count, double fps) {
  const int targets = frame_count - 1;
  std::vector<float> times(static_cast<std::size_t>(frame_count));
  std::vector<float> weights(static_cast<std::size_t>(frame_count) * static_cast<std::size_t>(targets), 0.0f);
  for (int f = 0; f < frame_count; ++f) {
    times[static_cast<std::size_t>(f)] = static_cast<float>(f / fps);
    if (f > 0) weights[static_cast<std::size_t>(f) * targets + static_cast<std::size_t>(f - 1)] = 1.0f;
  }
  const int time_view = builder.AddView(times.data(), times.size() * 4);
  const int input = builder.AddAccessor(time_view, TINYGLTF_COMPONENT_TYPE_FLOAT, times.size(), TINYGLTF_TYPE_SCALAR,
                                        {times.front()}, {times.back()});
  const int weight_view = builder.AddView(weights.data(), weights.size() * 4);
  const int output = builder.AddAccessor(weight_view, TINYGLTF_COMPONENT_TYPE_FLOAT, weights.size(), TINYGLTF_TYPE_SCALAR);
  tinygltf::Animation animation;
  animation.name = "subflow";
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = 0;
  channel.target_node = 0;
  channel.target_path = "weights";
  animation.channels.push_back(channel);
  builder.model().animations.push_back(animation);
}

}  // namespace

void GlbOptions::Check() const {
  if (!(fps > 0.0) || !std::isfinite(fps)) ThrowError("glb options", "fps", "expected a positive frame rate");
  if (!(up.norm() > 0.0) || !up.allFinite()) ThrowError("glb options", "up", "expected a non-zero direction");
}

GlbSummary WriteGlb(const ResultReader& result, const std::string& path, const GlbOptions& options,
                    Progress* progress) {
  options.Check();
  const int frame_count = result.frame_count();
  const double bytes_per_frame = result.vertex_count() * 12.0 * (1 + options.normals + options.colours);
  if (bytes_per_frame * frame_count > 4.0e9)
    ThrowError(path, "", "the sequence is too large for a .glb (" + std::to_string(frame_count) + " frames of " +
                             std::to_string(result.vertex_count()) + " vertices exceed 4 GB); use pc2 or mdd");
  GltfBuilder builder;
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.indices = AddIndices(builder, result.faces(), result.vertex_count());
  tinygltf::Mesh mesh;
  mesh.name = "surface";
  std::vector<tinygltf::Value> target_names;
  Floats base_positions, base_normals, base_colours;
  GlbSummary summary;

  ProgressBegin(progress, "glb", static_cast<std::size_t>(frame_count));
  // Without colours the flow is not read (a result may lack it).
  const std::vector<FlowKind> kinds = options.colours ? std::vector<FlowKind>{options.colour_flow} : std::vector<FlowKind>{};
  ForEachFrameFlow(result, kinds, [&](const ResultFrame& frame, const std::vector<Eigen::VectorXf>& magnitudes) {
    const bool first = frame.frame == result.first_frame();
    const Floats normals = options.normals ? UnitNormals(frame.V, result.faces()) : Floats();
    const Floats colours = options.colours ? LinearColours(magnitudes[0], options.colour_scale) : Floats();
    if (first) {
      base_positions = ToFloats(frame.V);
      primitive.attributes["POSITION"] = builder.AddVec3(base_positions, true);
      if (options.normals) primitive.attributes["NORMAL"] = builder.AddVec3(base_normals = normals, false);
      if (options.colours) primitive.attributes["COLOR_0"] = builder.AddVec3(base_colours = colours, false);
    } else {
      std::map<std::string, int> target;
      bool sparse = false, any_sparse = false;
      target["POSITION"] = builder.AddDelta(PositionDelta(frame.V, base_positions), options.sparse, true, &sparse);
      any_sparse |= sparse;
      if (options.normals)
        target["NORMAL"] = builder.AddDelta(Delta(normals, base_normals), options.sparse, false, &sparse);
      if (options.colours)
        target["COLOR_0"] = builder.AddDelta(Delta(colours, base_colours), options.sparse, false, &sparse);
      primitive.targets.push_back(target);
      target_names.emplace_back(vision::FrameName(frame.frame));
      mesh.weights.push_back(0.0);
      summary.sparse_targets += any_sparse;
    }
    ProgressUpdate(progress, static_cast<std::size_t>(frame.frame - result.first_frame() + 1));
  });
  ProgressEnd(progress);
  summary.morph_targets = static_cast<int>(primitive.targets.size());
  mesh.primitives.push_back(primitive);
  if (!target_names.empty()) {
    tinygltf::Value::Object extras;
    extras["targetNames"] = tinygltf::Value(target_names);
    mesh.extras = tinygltf::Value(extras);
  }
  tinygltf::Model& model = builder.model();
  model.meshes.push_back(mesh);

  tinygltf::Node node;
  node.name = "subflow result";
  node.mesh = 0;
  const Eigen::Quaterniond rotation = Eigen::Quaterniond::FromTwoVectors(options.up.normalized(), Eigen::Vector3d::UnitY());
  if (!rotation.isApprox(Eigen::Quaterniond::Identity()))
    node.rotation = {rotation.x(), rotation.y(), rotation.z(), rotation.w()};
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  if (frame_count > 1) AddAnimation(builder, frame_count, options.fps);
  model.asset.version = "2.0";
  model.asset.generator = "subflow export";

  AtomicFile file(path);
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, file.stream(), /*prettyPrint=*/false, /*writeBinary=*/true))
    ThrowError(path, "", "tinygltf could not write the glb");
  summary.bytes = static_cast<std::size_t>(file.stream().tellp());
  file.Commit();
  return summary;
}

}  // namespace subflow::output
