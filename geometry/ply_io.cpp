// Reading PLY (declared in geometry/ply_io.h).
#include "geometry/ply_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string_view>

#include <spdlog/spdlog.h>

#include "core/error.h"
#include "geometry/polygon_triangulation.h"
#include "geometry/text_parsing.h"

namespace subflow::geometry {
namespace {

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

struct ScalarTypeName {
  const char* name;
  ScalarType type;
};
constexpr ScalarTypeName kScalarTypeNames[] = {
    {"char", ScalarType::kInt8},      {"int8", ScalarType::kInt8},
    {"uchar", ScalarType::kUint8},    {"uint8", ScalarType::kUint8},
    {"short", ScalarType::kInt16},    {"int16", ScalarType::kInt16},
    {"ushort", ScalarType::kUint16},  {"uint16", ScalarType::kUint16},
    {"int", ScalarType::kInt32},      {"int32", ScalarType::kInt32},
    {"uint", ScalarType::kUint32},    {"uint32", ScalarType::kUint32},
    {"float", ScalarType::kFloat32},  {"float32", ScalarType::kFloat32},
    {"double", ScalarType::kFloat64}, {"float64", ScalarType::kFloat64}};

int ScalarSize(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kFloat64:
      return 8;
  }
  return 0;
}

bool IsInteger(ScalarType type) {
  return type != ScalarType::kFloat32 && type != ScalarType::kFloat64;
}

bool HostIsBigEndian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

enum class Encoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct Property {
  std::string name;
  ScalarType type = ScalarType::kFloat32;  // the value type, or the item type of a list
  bool is_list = false;
  ScalarType count_type = ScalarType::kUint8;
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t body_offset = 0;  // first byte after "end_header\n"
  int body_line = 0;       // 1-based line number of the first body line (ascii)
};

// The line starting at *pos without its "\n" or "\r\n"; false at the end of `bytes`.
bool NextLine(const std::string& bytes, size_t* pos, std::string_view* line) {
  if (*pos >= bytes.size()) return false;
  size_t end = bytes.find('\n', *pos);
  const size_t next = end == std::string::npos ? bytes.size() : end + 1;
  if (end == std::string::npos) end = bytes.size();
  if (end > *pos && bytes[end - 1] == '\r') --end;
  *line = std::string_view(bytes).substr(*pos, end - *pos);
  *pos = next;
  return true;
}

bool ParseScalarType(std::string_view name, ScalarType* type) {
  for (const ScalarTypeName& entry : kScalarTypeNames)
    if (name == entry.name) {
      *type = entry.type;
      return true;
    }
  return false;
}

std::string ScalarTypeError(std::string_view name) {
  return "unknown type \"" + std::string(name) +
         "\" (expected char, uchar, short, ushort, int, uint, float, double or "
         "int8, uint8, int16, uint16, int32, uint32, float32, float64)";
}

Header ParseHeader(const std::string& bytes, const std::string& source) {
  size_t pos = 0;
  std::string_view line;
  if (!NextLine(bytes, &pos, &line) || SplitTokens(line).size() != 1 ||
      SplitTokens(line)[0] != "ply")
    ThrowError(source, "header line 1", "expected the magic word \"ply\" (not a PLY file)");
  Header header;
  bool have_format = false;
  int line_number = 1;
  while (true) {
    if (!NextLine(bytes, &pos, &line))
      ThrowError(source, "header", "the file ends before \"end_header\"");
    ++line_number;
    const std::string where = "header line " + std::to_string(line_number);
    const std::vector<std::string_view> tokens = SplitTokens(line);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      if (tokens.size() != 3)
        ThrowError(source, where,
                   "expected \"format <ascii|binary_little_endian|binary_big_endian> 1.0\"");
      if (tokens[1] == "ascii")
        header.encoding = Encoding::kAscii;
      else if (tokens[1] == "binary_little_endian")
        header.encoding = Encoding::kBinaryLittleEndian;
      else if (tokens[1] == "binary_big_endian")
        header.encoding = Encoding::kBinaryBigEndian;
      else
        ThrowError(source, where,
                   "unsupported format \"" + std::string(tokens[1]) +
                       "\" (expected ascii, binary_little_endian or binary_big_endian)");
      if (tokens[2] != "1.0")
        ThrowError(source, where,
                   "unsupported version \"" + std::string(tokens[2]) + "\" (expected 1.0)");
      have_format = true;
    } else if (keyword == "element") {
      Element element;
      long long count = -1;
      if (tokens.size() == 3) {
        const auto [end, ec] =
            std::from_chars(tokens[2].data(), tokens[2].data() + tokens[2].size(), count);
        if (ec != std::errc() || end != tokens[2].data() + tokens[2].size()) count = -1;
      }
      if (count < 0 || count > std::numeric_limits<int>::max())
        ThrowError(source, where, "expected \"element <name> <count>\" with a count in [0, 2^31)");
      element.name = std::string(tokens[1]);
      element.count = count;
      for (const Element& other : header.elements)
        if (other.name == element.name)
          ThrowError(source, where, "element \"" + element.name + "\" is declared twice");
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty())
        ThrowError(source, where, "property declared before any element");
      Property property;
      if (tokens.size() == 3 && tokens[1] != "list") {
        if (!ParseScalarType(tokens[1], &property.type))
          ThrowError(source, where, ScalarTypeError(tokens[1]));
        property.name = std::string(tokens[2]);
      } else if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        if (!ParseScalarType(tokens[2], &property.count_type))
          ThrowError(source, where, ScalarTypeError(tokens[2]));
        if (!IsInteger(property.count_type))
          ThrowError(source, where,
                     "list count type must be an integer type, not " + std::string(tokens[2]));
        if (!ParseScalarType(tokens[3], &property.type))
          ThrowError(source, where, ScalarTypeError(tokens[3]));
        property.name = std::string(tokens[4]);
      } else {
        ThrowError(source, where,
                   "expected \"property <type> <name>\" or \"property list <count type> <item "
                   "type> <name>\"");
      }
      header.elements.back().properties.push_back(property);
    } else {
      ThrowError(source, where,
                 "unexpected \"" + std::string(keyword) +
                     "\" (expected format, element, property, comment, obj_info or end_header)");
    }
  }
  if (!have_format) ThrowError(source, "header", "no \"format\" line");
  header.body_offset = pos;
  header.body_line = line_number + 1;
  return header;
}

// Element instances in ascii: one line each, tokens in property order.
class AsciiBody {
 public:
  AsciiBody(const std::string& bytes, const Header& header, const std::string& source)
      : bytes_(bytes),
        pos_(header.body_offset),
        line_number_(header.body_line - 1),
        source_(source) {}

  void Begin(const Element& element, long long index) {
    element_ = &element;
    index_ = index;
    std::string_view line;
    do {
      if (!NextLine(bytes_, &pos_, &line))
        ThrowError(source_, element.name + " " + std::to_string(index),
                   "the file ends after " + std::to_string(index) + " of the " +
                       std::to_string(element.count) + " " + element.name +
                       " lines the header announces");
      ++line_number_;
      tokens_ = SplitTokens(line);
    } while (tokens_.empty());
    next_token_ = 0;
  }

  double Scalar(ScalarType type, const std::string& property) {
    if (next_token_ >= tokens_.size())
      ThrowError(source_, Where(), "the line ends before property \"" + property + "\"");
    const std::string_view token = tokens_[next_token_++];
    if (IsInteger(type)) {
      long long value = 0;
      if (!ParseInteger(token, &value))
        ThrowError(
            source_, Where(),
            "property \"" + property + "\": \"" + std::string(token) + "\" is not an integer");
      return static_cast<double>(value);
    }
    double value = 0.0;
    if (!ParseDouble(token, &value))
      ThrowError(source_, Where(),
                 "property \"" + property + "\": \"" + std::string(token) + "\" is not a number");
    // A float property holds a float: round as a binary file would have stored it.
    return type == ScalarType::kFloat32 ? static_cast<double>(static_cast<float>(value)) : value;
  }

  void End() {
    if (next_token_ != tokens_.size())
      ThrowError(source_, Where(),
                 "the line has " + std::to_string(tokens_.size()) +
                     " values, more than the header's properties describe");
  }

  void Finish() {
    std::string_view line;
    while (NextLine(bytes_, &pos_, &line)) {
      ++line_number_;
      if (!SplitTokens(line).empty())
        ThrowError(
            source_, "line " + std::to_string(line_number_),
            "data after the last element (the header's element counts do not match the data)");
    }
  }

  std::string Where() const {
    return element_->name + " " + std::to_string(index_) + " (line " +
           std::to_string(line_number_) + ")";
  }

 private:
  const std::string& bytes_;
  size_t pos_;
  int line_number_;
  const std::string& source_;
  const Element* element_ = nullptr;
  long long index_ = 0;
  std::vector<std::string_view> tokens_;
  size_t next_token_ = 0;
};

// Element instances in binary: packed values, in the file's byte order.
class BinaryBody {
 public:
  BinaryBody(const std::string& bytes, const Header& header, const std::string& source)
      : bytes_(bytes),
        pos_(header.body_offset),
        source_(source),
        swap_((header.encoding == Encoding::kBinaryBigEndian) != HostIsBigEndian()) {}

  void Begin(const Element& element, long long index) {
    element_ = &element;
    index_ = index;
  }

  double Scalar(ScalarType type, const std::string& property) {
    const int size = ScalarSize(type);
    if (pos_ + size > bytes_.size())
      ThrowError(source_, Where(),
                 "truncated binary data: the file ends inside property \"" + property +
                     "\" (the header announces " + std::to_string(element_->count) + " " +
                     element_->name + " elements)");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + pos_, size);
    pos_ += size;
    if (swap_) std::reverse(raw, raw + size);
    switch (type) {
      case ScalarType::kInt8:
        return Load<std::int8_t>(raw);
      case ScalarType::kUint8:
        return Load<std::uint8_t>(raw);
      case ScalarType::kInt16:
        return Load<std::int16_t>(raw);
      case ScalarType::kUint16:
        return Load<std::uint16_t>(raw);
      case ScalarType::kInt32:
        return Load<std::int32_t>(raw);
      case ScalarType::kUint32:
        return Load<std::uint32_t>(raw);
      case ScalarType::kFloat32:
        return Load<float>(raw);
      case ScalarType::kFloat64:
        return Load<double>(raw);
    }
    return 0.0;
  }

  void End() {}

  void Finish() {
    if (pos_ != bytes_.size())
      spdlog::warn("{}: {} bytes after the last element are ignored", source_,
                   bytes_.size() - pos_);
  }

  std::string Where() const { return element_->name + " " + std::to_string(index_); }

 private:
  template <class T>
  static double Load(const unsigned char* raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  const std::string& bytes_;
  size_t pos_;
  const std::string& source_;
  bool swap_;
  const Element* element_ = nullptr;
  long long index_ = 0;
};

// The fewest bytes one instance of `element` can take: binary, the sum of its scalar sizes
// and list-count sizes (a list may be empty); ascii, one character per value and one
// separator between values and at the end of the line.
long long SmallestInstanceBytes(const Element& element, Encoding encoding) {
  long long bytes = 0;
  for (const Property& property : element.properties)
    bytes += encoding == Encoding::kAscii ? 2
                                          : ScalarSize(property.is_list ? property.count_type
                                                                        : property.type);
  return bytes;
}

int FindProperty(const Element& element, std::initializer_list<const char*> names) {
  for (size_t p = 0; p < element.properties.size(); ++p)
    for (const char* name : names)
      if (element.properties[p].name == name) return static_cast<int>(p);
  return -1;
}

// The header's "vertex" and "face" elements, after checking that every element's count
// fits in the `data_bytes` that follow the header and that the mesh is not empty.
void FindMeshElements(const Header& header, long long data_bytes, const std::string& source,
                      const Element** vertex_element, const Element** face_element) {
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& element : header.elements) {
    if (element.name == "vertex") vertex = &element;
    if (element.name == "face") face = &element;
    // The data can hold at most data_bytes / (smallest size of an instance) instances, so a
    // larger count cannot be honest: refuse it before allocating what the header promises.
    const long long smallest = SmallestInstanceBytes(element, header.encoding);
    if (smallest > 0 && element.count > data_bytes / smallest)
      ThrowError(source, "element " + element.name,
                 "the header announces " + std::to_string(element.count) + " elements of at least " +
                     std::to_string(smallest) + " bytes but only " + std::to_string(data_bytes) +
                     " bytes of data follow (truncated file?)");
    if (smallest == 0 && element.count > 0)
      ThrowError(source, "element " + element.name,
                 "has " + std::to_string(element.count) +
                     " instances but no property (expected properties to read)");
  }
  if (!vertex) ThrowError(source, "header", "no \"vertex\" element");
  if (!face) ThrowError(source, "header", "no \"face\" element (expected a triangle mesh)");
  if (vertex->count == 0)
    ThrowError(source, "element vertex", "count is 0 (expected a non-empty mesh)");
  if (face->count == 0)
    ThrowError(source, "element face", "count is 0 (expected a non-empty mesh)");

  *vertex_element = vertex;
  *face_element = face;
}

template <class Body>
TriangleMesh ReadBody(Body& body, const Header& header, const std::string& bytes,
                      const std::string& source, VertexProperties* properties) {
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  FindMeshElements(header, static_cast<long long>(bytes.size() - header.body_offset), source, &vertex, &face);

  // Roles of the vertex properties: coordinate axis, extra column, or skipped list.
  std::vector<int> vertex_role(vertex->properties.size(), -1);  // 0..2 axis, 3+k extra k, -1 skip
  std::vector<std::string> extra_names;
  const char* kAxes[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const int p = FindProperty(*vertex, {kAxes[axis]});
    if (p < 0 || vertex->properties[p].is_list)
      ThrowError(source, "element vertex",
                 std::string("expected a scalar property \"") + kAxes[axis] + "\"");
    vertex_role[p] = axis;
  }
  for (size_t p = 0; p < vertex->properties.size(); ++p)
    if (vertex_role[p] < 0 && !vertex->properties[p].is_list) {
      vertex_role[p] = 3 + static_cast<int>(extra_names.size());
      extra_names.push_back(vertex->properties[p].name);
    }
  const int index_property = FindProperty(*face, {"vertex_indices", "vertex_index"});
  if (index_property < 0 || !face->properties[index_property].is_list ||
      !IsInteger(face->properties[index_property].type))
    ThrowError(source, "element face",
               "expected an integer list property \"vertex_indices\" (or \"vertex_index\")");

  TriangleMesh mesh;
  mesh.V.resize(vertex->count, 3);
  PolygonFaces faces;
  faces.corners.reserve(static_cast<size_t>(face->count) * 3);
  faces.starts.reserve(static_cast<size_t>(face->count) + 1);
  std::vector<int> corners;
  Eigen::MatrixXd extra(vertex->count, static_cast<Eigen::Index>(extra_names.size()));
  for (const Element& element : header.elements) {
    const bool is_vertex = &element == vertex;
    const bool is_face = &element == face;
    for (long long i = 0; i < element.count; ++i) {
      body.Begin(element, i);
      bool have_corners = false;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          const double value = body.Scalar(property.type, property.name);
          if (!std::isfinite(value))  // any element, any property: NaN / Inf is no data
            ThrowError(source, body.Where(),
                       (is_vertex && vertex_role[p] >= 0 && vertex_role[p] < 3 ? "coordinate " + property.name
                                                                               : "property \"" + property.name + "\"") +
                           " is " + (std::isnan(value) ? "NaN" : "infinite") + " (expected a finite number)");
          if (is_vertex && vertex_role[p] >= 0) {
            if (vertex_role[p] < 3)
              mesh.V(i, vertex_role[p]) = value;
            else
              extra(i, vertex_role[p] - 3) = value;
          }
          continue;
        }
        const double length = body.Scalar(property.count_type, property.name + " (list length)");
        if (length < 0)
          ThrowError(source, body.Where(), "negative list length in \"" + property.name + "\"");
        if (is_face && static_cast<int>(p) == index_property) {
          if (length < 3 || length > kMaxPolygonCorners)
            ThrowError(source, body.Where(),
                       "has " + std::to_string(static_cast<long long>(length)) +
                           " vertices; expected a polygon of 3 to " +
                           std::to_string(kMaxPolygonCorners));
          corners.clear();
          for (int k = 0; k < static_cast<int>(length); ++k) {
            const double index = body.Scalar(property.type, property.name);
            if (index < 0 || index >= static_cast<double>(vertex->count))
              ThrowError(source, body.Where(),
                         "vertex index " + std::to_string(static_cast<long long>(index)) +
                             " out of range [0, " + std::to_string(vertex->count) + ")");
            corners.push_back(static_cast<int>(index));
          }
          faces.Add(corners.data(), static_cast<int>(corners.size()));
          have_corners = true;
        } else {
          // Every list item takes at least one byte (binary) or token (ascii): a length
          // beyond the data left is caught by the reads themselves, item by item.
          for (long long k = 0; k < static_cast<long long>(length); ++k)
            body.Scalar(property.type, property.name);
        }
      }
      body.End();
      SUBFLOW_CHECK(!is_face || have_corners, "face without corners");
    }
  }
  body.Finish();
  int polygons = 0;
  mesh.F = TriangulatePolygons(faces, mesh.V, &polygons);
  if (polygons > 0)
    spdlog::warn("{}: {} of {} faces have more than 3 corners; triangulated into {} triangles",
                 source, polygons, face->count, mesh.face_count());

  if (properties) {
    properties->names = extra_names;
    properties->values.clear();
    for (size_t k = 0; k < extra_names.size(); ++k)
      properties->values[extra_names[k]] = extra.col(k);
  }
  return mesh;
}

}  // namespace

TriangleMesh ParsePly(const std::string& bytes, const std::string& source,
                      VertexProperties* properties) {
  const Header header = ParseHeader(bytes, source);
  if (header.encoding == Encoding::kAscii) {
    AsciiBody body(bytes, header, source);
    return ReadBody(body, header, bytes, source, properties);
  }
  BinaryBody body(bytes, header, source);
  return ReadBody(body, header, bytes, source, properties);
}

}  // namespace subflow::geometry
