#include "geometry/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "geometry/mesh_topology.h"
#include "geometry/obj_io.h"
#include "geometry/ply_io.h"

namespace subflow::geometry {
namespace {

namespace fs = std::filesystem;

enum class FileKind { kPly, kObj };

FileKind KindOf(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ply") return FileKind::kPly;
  if (extension == ".obj") return FileKind::kObj;
  ThrowError(path, "", "unsupported mesh file type \"" + extension + "\" (expected .ply or .obj)");
}

std::string ReadFileBytes(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) ThrowError(path, "", "no such file");
  if (fs::is_directory(path, error)) ThrowError(path, "", "is a directory (expected a mesh file)");
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowError(path, "", std::string("cannot open for reading: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<size_t>(std::max<std::streamoff>(size, 0)), '\0');
  if (!bytes.empty()) in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!in) ThrowError(path, "", "read error");
  if (bytes.empty()) ThrowError(path, "", "the file is empty (expected a PLY or OBJ mesh)");
  return bytes;
}

}  // namespace

TriangleMesh ReadMesh(const std::string& path, const MeshReadOptions& options,
                      VertexProperties* properties) {
  const FileKind kind = KindOf(path);
  const std::string bytes = ReadFileBytes(path);
  if (properties) *properties = VertexProperties{};
  TriangleMesh mesh =
      kind == FileKind::kPly ? ParsePly(bytes, path, properties) : ParseObj(bytes, path);
  if (options.require_manifold)
    MeshTopology(mesh.F, mesh.vertex_count(), path);  // throws naming `path`
  return mesh;
}

void WriteMesh(const std::string& path, const TriangleMesh& mesh,
               const VertexProperties* properties, PlyFormat ply_format) {
  const FileKind kind = KindOf(path);
  const fs::path parent = fs::path(path).parent_path();
  std::error_code error;
  if (!parent.empty() && !fs::is_directory(parent, error))
    ThrowError(path, "", "directory \"" + parent.string() + "\" does not exist");
  if (mesh.V.cols() != 3 || mesh.F.cols() != 3)
    ThrowError(path, "mesh", "expected #V×3 positions and #F×3 faces");
  for (int f = 0; f < mesh.face_count(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.F(f, k) < 0 || mesh.F(f, k) >= mesh.vertex_count())
        ThrowError(path, "face " + std::to_string(f),
                   "vertex index " + std::to_string(mesh.F(f, k)) + " out of range [0, " +
                       std::to_string(mesh.vertex_count()) + ") (refusing to write it)");
  if (kind == FileKind::kObj && properties && !properties->values.empty())
    ThrowError(path, "vertex properties",
               "OBJ cannot store per-vertex properties (write a .ply instead)");

  // Between two files of a sequence is a natural point to stop at (core/interrupt.h).
  ThrowIfInterrupted();
  // Write beside the destination and rename, so a reader never sees a half-written mesh.
  AtomicFile file(path);
  if (kind == FileKind::kPly)
    WritePly(file.stream(), mesh, properties, ply_format, path);
  else
    WriteObj(file.stream(), mesh, path);
  file.Commit();
}

}  // namespace subflow::geometry
