// Writing PLY (declared in geometry/ply_io.h).
#include "geometry/ply_io.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <set>

#include "core/error.h"

namespace subflow::geometry {
namespace {

bool HostIsBigEndian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

void AppendFloat(std::string* buffer, float value, bool swap) {
  unsigned char raw[4];
  std::memcpy(raw, &value, 4);
  if (swap) std::reverse(raw, raw + 4);
  buffer->append(reinterpret_cast<const char*>(raw), 4);
}

void AppendDouble(std::string* buffer, double value, bool swap) {
  unsigned char raw[8];
  std::memcpy(raw, &value, 8);
  if (swap) std::reverse(raw, raw + 8);
  buffer->append(reinterpret_cast<const char*>(raw), 8);
}

void AppendInt32(std::string* buffer, std::int32_t value, bool swap) {
  unsigned char raw[4];
  std::memcpy(raw, &value, 4);
  if (swap) std::reverse(raw, raw + 4);
  buffer->append(reinterpret_cast<const char*>(raw), 4);
}

}  // namespace

std::vector<std::string> PropertyWriteOrder(const VertexProperties& properties, int vertex_count,
                                            const std::string& source) {
  std::vector<std::string> names = properties.names;
  if (names.empty())
    for (const auto& entry : properties.values) names.push_back(entry.first);
  std::set<std::string> seen;
  for (const std::string& name : names) {
    const std::string field = "vertex property \"" + name + "\"";
    const auto it = properties.values.find(name);
    if (it == properties.values.end())
      ThrowError(source, field, "listed in names but has no values");
    if (it->second.size() != vertex_count)
      ThrowError(source, field,
                 "has " + std::to_string(it->second.size()) + " values; expected one per vertex (" +
                     std::to_string(vertex_count) + ")");
    if (name == "x" || name == "y" || name == "z")
      ThrowError(source, field, "collides with a coordinate");
    if (name.empty() || name.find_first_of(" \t\r\n") != std::string::npos)
      ThrowError(source, field, "expected a non-empty name without white space");
    if (!seen.insert(name).second) ThrowError(source, field, "listed twice in names");
  }
  if (seen.size() != properties.values.size())
    ThrowError(source, "vertex properties", "values are given for properties missing from names");
  return names;
}

void WritePly(std::ostream& out, const TriangleMesh& mesh, const VertexProperties* properties,
              PlyFormat format, const std::string& source) {
  const int n = mesh.vertex_count();
  const int m = mesh.face_count();
  const std::vector<std::string> names =
      properties ? PropertyWriteOrder(*properties, n, source) : std::vector<std::string>{};
  std::vector<const Eigen::VectorXd*> columns;
  for (const std::string& name : names) columns.push_back(&properties->values.at(name));
  for (int v = 0; v < n; ++v)
    if (!mesh.V.row(v).allFinite())
      ThrowError(source, "vertex " + std::to_string(v),
                 "non-finite coordinate (refusing to write it)");

  std::string text = "ply\nformat ";
  const bool exact = format == PlyFormat::kBinaryLittleEndianDouble;
  const std::string scalar = exact ? "double" : "float";
  text += format == PlyFormat::kAscii ? "ascii 1.0\n" : "binary_little_endian 1.0\n";
  text += "comment written by subflow\n";
  text += "element vertex " + std::to_string(n) + "\n";
  for (const char* axis : {"x", "y", "z"}) text += "property " + scalar + " " + axis + "\n";
  for (const std::string& name : names) text += "property " + scalar + " " + name + "\n";
  text += "element face " + std::to_string(m) + "\n";
  text += "property list uchar int vertex_indices\nend_header\n";

  if (format == PlyFormat::kAscii) {
    char number[32];
    for (int v = 0; v < n; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        std::snprintf(number, sizeof(number), axis ? " %.9g" : "%.9g",
                      static_cast<double>(static_cast<float>(mesh.V(v, axis))));
        text += number;
      }
      for (const Eigen::VectorXd* column : columns) {
        std::snprintf(number, sizeof(number), " %.9g",
                      static_cast<double>(static_cast<float>((*column)(v))));
        text += number;
      }
      text += '\n';
    }
    for (int f = 0; f < m; ++f)
      text += "3 " + std::to_string(mesh.F(f, 0)) + " " + std::to_string(mesh.F(f, 1)) + " " +
              std::to_string(mesh.F(f, 2)) + "\n";
  } else {
    const bool swap = HostIsBigEndian();
    text.reserve(text.size() + static_cast<size_t>(n) * (exact ? 8 : 4) * (3 + names.size()) +
                 static_cast<size_t>(m) * 13);
    const auto append = [&](double value) {
      if (exact)
        AppendDouble(&text, value, swap);
      else
        AppendFloat(&text, static_cast<float>(value), swap);
    };
    for (int v = 0; v < n; ++v) {
      for (int axis = 0; axis < 3; ++axis) append(mesh.V(v, axis));
      for (const Eigen::VectorXd* column : columns) append((*column)(v));
    }
    for (int f = 0; f < m; ++f) {
      text += static_cast<char>(3);
      for (int k = 0; k < 3; ++k) AppendInt32(&text, mesh.F(f, k), swap);
    }
  }
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
}

}  // namespace subflow::geometry
