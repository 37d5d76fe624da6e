#include "output/point_cache.h"

#include <cmath>

#include "core/error.h"
#include "geometry/obj_io.h"
#include "output/binary_stream.h"
#include "core/atomic_file.h"

namespace subflow::output {
namespace {

// Streams every frame's positions as float32 x y z in `order`.
void WriteFramePositions(const ResultReader& result, std::ostream& out, ByteOrder order,
                         Progress* progress) {
  ProgressBegin(progress, "point cache", static_cast<std::size_t>(result.frame_count()));
  for (int i = 0; i < result.frame_count(); ++i) {
    const geometry::Positions V = result.ReadFrame(i).V;
    std::string bytes(static_cast<std::size_t>(V.size()) * 4, '\0');
    for (Eigen::Index k = 0; k < V.size(); ++k)  // row-major: x y z of each vertex in turn
      EncodeFloat32(static_cast<float>(V.data()[k]), order, &bytes[static_cast<std::size_t>(4 * k)]);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ProgressUpdate(progress, static_cast<std::size_t>(i + 1));
  }
  ProgressEnd(progress);
}

}  // namespace

void WritePc2(const ResultReader& result, const std::string& path, float start_frame,
              Progress* progress) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  constexpr ByteOrder kOrder = ByteOrder::kLittleEndian;
  out.write("POINTCACHE2\0", 12);
  WriteInt32(out, 1, kOrder);
  WriteInt32(out, result.vertex_count(), kOrder);
  WriteFloat32(out, start_frame, kOrder);
  WriteFloat32(out, 1.0f, kOrder);
  WriteInt32(out, result.frame_count(), kOrder);
  WriteFramePositions(result, out, kOrder, progress);
  file.Commit();
}

void WriteMdd(const ResultReader& result, const std::string& path, double fps, Progress* progress) {
  if (!(fps > 0.0) || !std::isfinite(fps))
    ThrowError(path, "fps", "expected a positive frame rate, got " + std::to_string(fps));
  AtomicFile file(path);
  std::ostream& out = file.stream();
  constexpr ByteOrder kOrder = ByteOrder::kBigEndian;
  WriteInt32(out, result.frame_count(), kOrder);
  WriteInt32(out, result.vertex_count(), kOrder);
  for (int i = 0; i < result.frame_count(); ++i) WriteFloat32(out, static_cast<float>(i / fps), kOrder);
  WriteFramePositions(result, out, kOrder, progress);
  file.Commit();
}

void WriteBaseObj(const ResultReader& result, const std::string& path) {
  AtomicFile file(path);
  const geometry::TriangleMesh first{result.ReadFrame(0).V, result.faces()};
  geometry::WriteObj(file.stream(), first, path);
  file.Commit();
}

}  // namespace subflow::output
