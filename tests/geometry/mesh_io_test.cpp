#include "geometry/mesh_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

namespace fs = std::filesystem;

// A closed octahedron with irregular (non-float-representable) coordinates.
TriangleMesh PerturbedOctahedron() {
  TriangleMesh mesh;
  mesh.V.resize(6, 3);
  mesh.V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> noise(-0.1, 0.1);
  for (int i = 0; i < mesh.V.size(); ++i) mesh.V.data()[i] += noise(random) / 3.0;
  mesh.F.resize(8, 3);
  mesh.F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return mesh;
}

VertexProperties FlowProperties(int vertex_count) {
  VertexProperties properties;
  properties.names = {"vx", "vy", "vz", "confidence"};
  for (size_t k = 0; k < properties.names.size(); ++k)
    properties.values[properties.names[k]] =
        Eigen::VectorXd::LinSpaced(vertex_count, 0.1 * k, 1.0 / 3.0 + k);
  return properties;
}

double AsFloat(double value) { return static_cast<double>(static_cast<float>(value)); }

class MeshIo : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  std::string WriteFile(const std::string& name, const std::string& bytes) const {
    const std::string path = Path(name);
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  static std::string ReadBytes(const std::string& path) { return test::ReadTextFile(path); }

  // Reading `path` must fail with a message holding the path and every fragment.
  static void ExpectReadError(const std::string& path, std::initializer_list<std::string> fragments,
                              const MeshReadOptions& options = {}) {
    try {
      ReadMesh(path, options);
      ADD_FAILURE() << "reading " << path << " did not throw";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      for (const std::string& fragment : fragments)
        EXPECT_NE(message.find(fragment), std::string::npos)
            << "missing \"" << fragment << "\" in: " << message;
    }
  }

  const test::TemporaryDirectory dir_{
      std::string("mesh_io_") + ::testing::UnitTest::GetInstance()->current_test_info()->name()};
};

// Binary and ASCII PLY store float, so a round trip must give back exactly the float
// rounding of every coordinate and property (tolerance 0 on the float values).
void ExpectFloatRoundTrip(const TriangleMesh& mesh, const VertexProperties& properties,
                          const TriangleMesh& read, const VertexProperties& read_properties) {
  ASSERT_EQ(read.vertex_count(), mesh.vertex_count());
  ASSERT_EQ(read.face_count(), mesh.face_count());
  for (int i = 0; i < mesh.V.size(); ++i)
    EXPECT_EQ(read.V.data()[i], AsFloat(mesh.V.data()[i])) << i;
  EXPECT_EQ(read.F, mesh.F);
  EXPECT_EQ(read_properties.names, properties.names);
  for (const std::string& name : properties.names)
    for (int v = 0; v < mesh.vertex_count(); ++v)
      EXPECT_EQ(read_properties.values.at(name)(v), AsFloat(properties.values.at(name)(v)))
          << name << " " << v;
}

TEST_F(MeshIo, BinaryPlyRoundTripKeepsFloatValuesAndPropertiesExactly) {
  const TriangleMesh mesh = PerturbedOctahedron();
  const VertexProperties properties = FlowProperties(mesh.vertex_count());
  WriteMesh(Path("m.ply"), mesh, &properties);
  VertexProperties read_properties;
  const TriangleMesh read = ReadMesh(Path("m.ply"), {}, &read_properties);
  ExpectFloatRoundTrip(mesh, properties, read, read_properties);
  EXPECT_FALSE(fs::exists(Path(".m.ply.partial")));
}

TEST_F(MeshIo, AsciiPlyRoundTripKeepsFloatValuesAndPropertiesExactly) {
  const TriangleMesh mesh = PerturbedOctahedron();
  const VertexProperties properties = FlowProperties(mesh.vertex_count());
  WriteMesh(Path("m.ply"), mesh, &properties, PlyFormat::kAscii);
  EXPECT_EQ(ReadBytes(Path("m.ply")).rfind("ply\nformat ascii 1.0\n", 0), 0u);
  VertexProperties read_properties;
  const TriangleMesh read = ReadMesh(Path("m.ply"), {}, &read_properties);
  ExpectFloatRoundTrip(mesh, properties, read, read_properties);
}

TEST_F(MeshIo, DoublePlyRoundTripKeepsDoublesAndPropertiesExactly) {
  // The stage folders (docs/stages.md) hand exact doubles from one stage to the next.
  const TriangleMesh mesh = PerturbedOctahedron();
  const VertexProperties properties = FlowProperties(mesh.vertex_count());
  WriteMesh(Path("m.ply"), mesh, &properties, PlyFormat::kBinaryLittleEndianDouble);
  EXPECT_NE(ReadBytes(Path("m.ply")).find("property double x\n"), std::string::npos);
  VertexProperties read_properties;
  const TriangleMesh read = ReadMesh(Path("m.ply"), {}, &read_properties);
  EXPECT_EQ(read.V, mesh.V);
  EXPECT_EQ(read.F, mesh.F);
  for (const auto& [name, values] : properties.values) EXPECT_EQ(read_properties.values.at(name), values) << name;
  // The float format would not have kept them.
  WriteMesh(Path("f.ply"), mesh, &properties);
  EXPECT_NE(ReadMesh(Path("f.ply")).V, mesh.V);
}

TEST_F(MeshIo, ObjRoundTripKeepsDoublesExactly) {
  // OBJ is text with 17 significant digits: every double comes back bit for bit.
  const TriangleMesh mesh = PerturbedOctahedron();
  WriteMesh(Path("m.obj"), mesh);
  const TriangleMesh read = ReadMesh(Path("m.obj"));
  EXPECT_EQ(read.V, mesh.V);
  EXPECT_EQ(read.F, mesh.F);
}

TEST_F(MeshIo, BinaryOutputFollowsTheOutputContract) {
  // OUTPUT.md: binary little-endian, float x y z, float vx vy vz, triangles.
  const TriangleMesh mesh = PerturbedOctahedron();
  VertexProperties flow = FlowProperties(mesh.vertex_count());
  flow.names = {"vx", "vy", "vz"};
  flow.values.erase("confidence");
  WriteMesh(Path("000000.ply"), mesh, &flow);
  const std::string bytes = ReadBytes(Path("000000.ply"));
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment written by subflow\nelement vertex 6\n"
      "property float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
      "property float vz\nelement face 8\nproperty list uchar int vertex_indices\nend_header\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  EXPECT_EQ(bytes.size(), header.size() + 6 * 6 * 4 + 8 * (1 + 3 * 4));
  float first_x;
  std::memcpy(&first_x, bytes.data() + header.size(), 4);  // this test host is little-endian
  EXPECT_EQ(first_x, static_cast<float>(mesh.V(0, 0)));
}

TEST_F(MeshIo, ReadsTheBlobGroundTruthMesh) {
  const std::string path =
      std::string(SUBFLOW_SHARED_DIR) + "/data/blob/groundtruth/mesh/000000.ply";
  const TriangleMesh mesh = ReadMesh(path);  // also checks manifoldness
  EXPECT_EQ(mesh.vertex_count(), 10242);
  EXPECT_EQ(mesh.face_count(), 20480);
  // A sphere of radius 0.1 m displaced by at most 8 mm along its normals.
  const Eigen::VectorXd radius = mesh.V.rowwise().norm();
  EXPECT_GT(radius.minCoeff(), 0.08);
  EXPECT_LT(radius.maxCoeff(), 0.12);
}

template <class T>
void AppendBigEndian(std::string* bytes, T value) {
  char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  std::reverse(raw, raw + sizeof(T));  // the test host is little-endian
  bytes->append(raw, sizeof(T));
}

TEST_F(MeshIo, ReadsBigEndianPlyWithMixedTypesAndSkipsOtherElements) {
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment every scalar type once\n"
      "element vertex 4\nproperty double x\nproperty float32 y\nproperty int16 z\nproperty uint8 "
      "red\n"
      "property list uchar int8 tags\n"
      "element material 2\nproperty uint32 id\nproperty list ushort float64 values\n"
      "element face 4\nproperty uint8 flags\nproperty list uint16 uint32 vertex_index\n"
      "property list int8 float texcoord\nend_header\n";
  const double x[4] = {0.1, 1.0, 0.0, 0.0};
  const float y[4] = {0.0f, 0.0f, 1.5f, 0.0f};
  const std::int16_t z[4] = {0, 0, 0, -3};
  for (int v = 0; v < 4; ++v) {
    AppendBigEndian<double>(&bytes, x[v]);
    AppendBigEndian<float>(&bytes, y[v]);
    AppendBigEndian<std::int16_t>(&bytes, z[v]);
    AppendBigEndian<std::uint8_t>(&bytes, static_cast<std::uint8_t>(200 + v));
    AppendBigEndian<std::uint8_t>(&bytes, 2);
    AppendBigEndian<std::int8_t>(&bytes, -1);
    AppendBigEndian<std::int8_t>(&bytes, 1);
  }
  for (int m = 0; m < 2; ++m) {
    AppendBigEndian<std::uint32_t>(&bytes, 7);
    AppendBigEndian<std::uint16_t>(&bytes, 3);
    for (int k = 0; k < 3; ++k) AppendBigEndian<double>(&bytes, 0.5 * k);
  }
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  for (const auto& face : faces) {
    AppendBigEndian<std::uint8_t>(&bytes, 1);
    AppendBigEndian<std::uint16_t>(&bytes, 3);
    for (int k = 0; k < 3; ++k)
      AppendBigEndian<std::uint32_t>(&bytes, static_cast<std::uint32_t>(face[k]));
    AppendBigEndian<std::int8_t>(&bytes, 2);
    AppendBigEndian<float>(&bytes, 0.25f);
    AppendBigEndian<float>(&bytes, 0.75f);
  }
  VertexProperties properties;
  const TriangleMesh mesh = ReadMesh(WriteFile("be.ply", bytes), {}, &properties);
  ASSERT_EQ(mesh.vertex_count(), 4);
  ASSERT_EQ(mesh.face_count(), 4);
  EXPECT_EQ(mesh.V(0, 0), 0.1);  // a double property stays double
  EXPECT_EQ(mesh.V(2, 1), 1.5);
  EXPECT_EQ(mesh.V(3, 2), -3.0);
  for (int f = 0; f < 4; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.F(f, k), faces[f][k]);
  ASSERT_EQ(properties.names, std::vector<std::string>{"red"});
  EXPECT_EQ(properties.values.at("red")(3), 203.0);
}

TEST_F(MeshIo, ReadsAsciiPlyWithCrlfCommentsAndTrailingElements) {
  const std::string text =
      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info nothing\r\n"
      "element vertex 4\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nproperty "
      "uchar alpha\r\n"
      "element face 4\r\nproperty list int int vertex_indices\r\nproperty int label\r\n"
      "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
      "0 0 0 255\r\n1 0 0 255\r\n0 1 0 255\r\n0 0 +1e0 128\r\n"
      "3 0 2 1 5\r\n3 0 1 3 5\r\n3 1 2 3 5\r\n3 2 0 3 5\r\n0 1\r\n\r\n";
  VertexProperties properties;
  const TriangleMesh mesh = ReadMesh(WriteFile("crlf.ply", text), {}, &properties);
  ASSERT_EQ(mesh.vertex_count(), 4);
  EXPECT_EQ(mesh.V(3, 2), 1.0);
  EXPECT_EQ(mesh.F(3, 1), 0);
  EXPECT_EQ(properties.values.at("alpha")(3), 128.0);
}

TEST_F(MeshIo, ReadsObjCornerFormsNegativeIndicesAndIgnoresAttributes) {
  const std::string text =
      "# a tetrahedron\nmtllib none.mtl\no tet\nv 0 0 0\nv 1 0 0 1.0\nv 0 1 0 0.5 0.5 0.5\n"
      "vt 0 0\nvn 0 0 1\nusemtl red\ns off\n"
      "f 1/1/1 3/1/1 2/1/1\nv 0 0 1\nf 1//1 2//1 -1//1   # negative = relative\n"
      "f 2/1 3/1 4/1\ng side\nf -2 -4 -1\n";
  const TriangleMesh mesh = ReadMesh(WriteFile("tet.obj", text));
  ASSERT_EQ(mesh.vertex_count(), 4);
  Faces expected(4, 3);
  expected << 0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3;
  EXPECT_EQ(mesh.F, expected);
  EXPECT_EQ(mesh.V(3, 2), 1.0);
}

const char* const kAsciiHeader =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float "
    "z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
const char* const kTetrahedronVertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";

TEST_F(MeshIo, BadPlyFilesNameTheFileTheElementAndTheExpectation) {
  const std::string header = kAsciiHeader, vertices = kTetrahedronVertices;
  ExpectReadError(
      WriteFile("segment.ply", header + vertices + "2 0 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"),
      {"face 0", "has 2 vertices", "expected a polygon of 3 to"});
  ExpectReadError(
      WriteFile("nan.ply",
                header + "0 0 0\n1 nan 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"),
      {"vertex 1", "coordinate y is NaN", "expected a finite number"});
  ExpectReadError(
      WriteFile("inf.ply",
                header + "0 0 0\n1 0 0\n0 1 -inf\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"),
      {"vertex 2", "infinite"});
  ExpectReadError(
      WriteFile("range.ply", header + vertices + "3 0 2 1\n3 0 1 9\n3 1 2 3\n3 2 0 3\n"),
      {"face 1", "vertex index 9 out of range [0, 4)"});
  ExpectReadError(WriteFile("short.ply", header + vertices + "3 0 2 1\n3 0 1 3\n"),
                  {"face 2", "ends after 2 of the 4 face lines"});
  ExpectReadError(
      WriteFile("fewvalues.ply",
                header + "0 0 0\n1 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n"),
      {"vertex 1 (line 11)", "before property \"z\""});
  ExpectReadError(WriteFile("garbage.ply", "ply\nformat ascii 1.0\nhello world\nend_header\n"),
                  {"header line 3", "unexpected \"hello\""});
  ExpectReadError(WriteFile("magic.ply", "solid cube\nfacet normal 0 0 1\n"),
                  {"header line 1", "\"ply\""});
  ExpectReadError(WriteFile("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
                  {"header line 2", "unsupported format \"binary_middle_endian\""});
  ExpectReadError(
      WriteFile("type.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n"),
      {"header line 4", "unknown type \"float128\""});
  ExpectReadError(
      WriteFile("nofaces.ply",
                "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                "property float z\nend_header\n0 0 0\n"),
      {"no \"face\" element"});
  ExpectReadError(WriteFile("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"),
                  {"end_header"});
  ExpectReadError(WriteFile("empty.ply", ""), {"empty"});
  ExpectReadError(Path("missing.ply"), {"no such file"});
  ExpectReadError(WriteFile("mesh.stl", "solid"), {"unsupported mesh file type \".stl\""});
}

TEST_F(MeshIo, TruncatedOrNonFiniteBinaryPlyIsRejected) {
  const TriangleMesh mesh = PerturbedOctahedron();
  WriteMesh(Path("full.ply"), mesh);
  const std::string bytes = ReadBytes(Path("full.ply"));
  ExpectReadError(WriteFile("cut.ply", bytes.substr(0, bytes.size() - 5)),
                  {"face 7", "truncated binary data", "announces 8 face elements"});
  // Too short for the vertices the header announces: refused before reading (or allocating).
  ExpectReadError(WriteFile("cut_vertices.ply", bytes.substr(0, bytes.size() - 8 * 13 - 10)),
                  {"element vertex", "announces 6 elements of at least 12 bytes", "truncated"});
  // The first vertex's y coordinate sits 4 bytes after the header.
  std::string nan_bytes = bytes;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan_bytes[bytes.find("end_header\n") + 11 + 4], &nan, 4);
  ExpectReadError(WriteFile("nan_binary.ply", nan_bytes), {"vertex 0", "coordinate y is NaN"});
}

TEST_F(MeshIo, BadObjFilesNameTheLineAndTheFace) {
  ExpectReadError(WriteFile("segment.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2\n"),
                  {"line 5 (face 0)", "has 2 vertices", "expected a polygon of at least 3"});
  ExpectReadError(WriteFile("range.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 7\n"),
                  {"line 5 (face 1)", "vertex index 7 out of range [1, 3]"});
  ExpectReadError(WriteFile("relative.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 1 1 0\n"),
                  {"line 3 (face 0)", "relative vertex index -3"});
  ExpectReadError(WriteFile("zero.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n"),
                  {"line 4", "non-zero integer"});
  ExpectReadError(WriteFile("nan.obj", "v 0 0 0\nv 1 NaN 0\nv 1 1 0\nf 1 2 3\n"),
                  {"line 2 (vertex 1)", "coordinate y is NaN"});
  ExpectReadError(WriteFile("empty.obj", "# nothing\n"), {"no \"v\" statement"});
}

// Text numbers outside double's range: 1e400 overflows to infinity (rejected as a
// coordinate), 1e-400 underflows to 0 (accepted), in both text formats; a number with
// trailing characters is not a number. Exact comparisons: 0 is what strtod gives.
TEST_F(MeshIo, TextNumbersOverflowToInfinityAndUnderflowToZero) {
  const TriangleMesh obj =
      ReadMesh(WriteFile("tiny.obj", "v 0 0 1e-400\nv 1 0 0\nv 0 1 -1e-400\nf 1 2 3\n"));
  EXPECT_EQ(obj.V(0, 2), 0.0);
  EXPECT_EQ(obj.V(2, 2), 0.0);
  ExpectReadError(WriteFile("huge.obj", "v 0 0 0\nv 1 1e400 0\nv 1 1 0\nf 1 2 3\n"),
                  {"line 2 (vertex 1)", "coordinate y is infinite"});
  const std::string faces = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
  const TriangleMesh ply = ReadMesh(
      WriteFile("tiny.ply", std::string(kAsciiHeader) + "0 0 1e-400\n1 0 0\n0 1 0\n0 0 1\n" + faces));
  EXPECT_EQ(ply.V(0, 2), 0.0);
  ExpectReadError(
      WriteFile("huge.ply", std::string(kAsciiHeader) + "0 0 0\n1 0 0\n0 1 1e400\n0 0 1\n" + faces),
      {"vertex 2", "infinite"});
  ExpectReadError(
      WriteFile("trailing.ply", std::string(kAsciiHeader) + "0 0 0\n1e999x 0 0\n0 1 0\n0 0 1\n" + faces),
      {"vertex 1", "is not a number"});
}

TEST_F(MeshIo, NonManifoldInputIsRejectedUnlessAllowed) {
  const std::string header5 =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float "
      "z\n";
  const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n";
  // Fin: edge (0, 1) borders three faces.
  const std::string fin =
      WriteFile("fin.ply", header5 +
                               "element face 3\nproperty list uchar int vertex_indices\n"
                               "end_header\n" +
                               vertices + "3 0 1 2\n3 1 0 3\n3 1 0 4\n");
  ExpectReadError(fin, {"edge (1, 0)", "non-manifold"});
  MeshReadOptions lenient;
  lenient.require_manifold = false;
  EXPECT_EQ(ReadMesh(fin, lenient).face_count(), 3);
  // Bowtie: two triangles meeting only at vertex 0.
  const std::string bowtie_vertices = "0 0 0\n1 0 0\n1 1 0\n-1 0 0\n-1 -1 0\n";
  ExpectReadError(
      WriteFile("bowtie.ply", header5 +
                                  "element face 2\nproperty list uchar int vertex_indices\n"
                                  "end_header\n" +
                                  bowtie_vertices + "3 0 1 2\n3 0 3 4\n"),
      {"vertex 0", "non-manifold vertex"});
}

TEST_F(MeshIo, WritersRefuseMissingDirectoriesAndBadPropertiesAndLeaveNoTemporaryFile) {
  const TriangleMesh mesh = PerturbedOctahedron();
  EXPECT_THROW(WriteMesh(Path("no/such/dir/m.ply"), mesh), Error);
  VertexProperties short_column;
  short_column.values["vx"] = Eigen::VectorXd::Zero(3);
  try {
    WriteMesh(Path("m.ply"), mesh, &short_column);
    ADD_FAILURE() << "a property with 3 values for 6 vertices was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vertex property \"vx\""), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(Path("m.ply")));
  EXPECT_FALSE(fs::exists(Path(".m.ply.partial")));
  const VertexProperties flow = FlowProperties(mesh.vertex_count());
  EXPECT_THROW(WriteMesh(Path("m.obj"), mesh, &flow), Error);
  // Overwriting replaces the old file.
  WriteMesh(Path("m.ply"), mesh);
  TriangleMesh moved = mesh;
  moved.V.array() += 1.0;
  WriteMesh(Path("m.ply"), moved);
  EXPECT_EQ(ReadMesh(Path("m.ply")).V(0, 0), AsFloat(moved.V(0, 0)));
}

}  // namespace
}  // namespace subflow::geometry
