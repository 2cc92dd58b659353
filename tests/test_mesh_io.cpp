#include "core/error.h"
#include "core/mesh.h"

#include "tests/temp_dir.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class MeshIoTest : public test::TempDirTest {
 protected:

  fs::path write(const std::string& name, std::string_view bytes) const {
    const fs::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    EXPECT_TRUE(out.good()) << path;
    return path;
  }

  fs::path write_gz(const std::string& name, std::string_view bytes) const {
    const fs::path path = dir_ / name;
    gzFile gz = gzopen(path.string().c_str(), "wb");
    EXPECT_NE(gz, nullptr) << path;
    EXPECT_EQ(gzwrite(gz, bytes.data(), static_cast<unsigned>(bytes.size())), static_cast<int>(bytes.size()));
    EXPECT_EQ(gzclose(gz), Z_OK);
    return path;
  }

  // Writes `bytes` to `name` and expects load_mesh to throw an InputError
  // naming the file and containing every one of `keys`.
  void expect_error(const std::string& name, std::string_view bytes,
                    std::initializer_list<std::string_view> keys) const;

};

using MeshIoPly = MeshIoTest;
using MeshIoObj = MeshIoTest;
using MeshIoGzip = MeshIoTest;
using MeshIoErrors = MeshIoTest;

// Loads `path` expecting an InputError whose message names the file and
// contains every one of `keys`.
void expect_input_error(const fs::path& path, std::initializer_list<std::string_view> keys) {
  try {
    load_mesh(path);
    ADD_FAILURE() << "no InputError for " << path;
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    for (const std::string_view key : keys)
      EXPECT_NE(message.find(key), std::string::npos) << "'" << key << "' not in: " << message;
  }
}

void MeshIoTest::expect_error(const std::string& name, std::string_view bytes,
                              std::initializer_list<std::string_view> keys) const {
  expect_input_error(write(name, bytes), keys);
}

// Appends the bytes of `value` in the given byte order.
template <typename T>
void put(std::string& out, T value, bool big_endian) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

// A unit square (vertices 0..3) as a quad plus a triangle 0 2 4 with vertex 4 off the plane.
const char* const kAsciiPlyWithExtras =
    "ply\r\n"
    "format ascii 1.0\r\n"
    "comment made by hand\r\n"
    "obj_info nothing\r\n"
    "element vertex 5\r\n"
    "property float x\r\n"
    "property float nx\r\n"
    "property double y\r\n"
    "property list uchar float weights\r\n"
    "property float z\r\n"
    "property float ny\r\n"
    "element material 2\r\n"
    "property list int int ids\r\n"
    "property uchar red\r\n"
    "element face 2\r\n"
    "property uchar flags\r\n"
    "property list uchar int vertex_indices\r\n"
    "property list uchar float texcoord\r\n"
    "element edge 1\r\n"
    "property int vertex1\r\n"
    "property int vertex2\r\n"
    "end_header\r\n"
    "0 9 0 2 0.5 0.5 0 9\r\n"
    "  1   9 0 0 0 9\r\n"
    "1 9 1 1 7 0 9\r\n"
    "0\t9 1 3 1 2 3 0 9\r\n"
    "0.5 9 0.5 0 +2 9\r\n"
    "3 1 2 3 255\r\n"
    "0 0\r\n"
    "\r\n"
    "7 4 0 1 2 3 2 0.5 0.5\r\n"
    "0 3 0 2 4 0\r\n"
    "0 1\r\n";

TEST_F(MeshIoPly, AsciiQuadWithExtraElementsAndPropertiesSkipped) {
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("square.ply", kAsciiPlyWithExtras), &report);
  ASSERT_EQ(mesh.positions.size(), 5u);
  EXPECT_EQ(mesh.positions[1], vec3(1, 0, 0));
  EXPECT_EQ(mesh.positions[2], vec3(1, 1, 0));
  EXPECT_EQ(mesh.positions[3], vec3(0, 1, 0));
  EXPECT_EQ(mesh.positions[4], vec3(0.5f, 0.5f, 2));
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], glm::uvec3(0, 2, 4));
  EXPECT_EQ(report.faces_in_file, 2u);
  EXPECT_EQ(report.triangles_loaded, 3u);
  EXPECT_EQ(report.degenerate_dropped, 0u);
}

// A binary PLY with a quad, a triangle, an element to skip before the faces
// and extra properties (scalar and list) on both vertices and faces.
std::string binary_ply(bool big_endian, bool double_coords, const std::string& index_name) {
  std::string out = "ply\nformat ";
  out += big_endian ? "binary_big_endian 1.0\n" : "binary_little_endian 1.0\n";
  const std::string coord = double_coords ? "float64" : "float";
  out += "comment binary test\nelement vertex 5\nproperty " + coord + " x\nproperty " + coord + " y\n";
  out += "property uint8 alpha\nproperty list uchar short extra\nproperty " + coord + " z\n";
  out += "element skipme 2\nproperty list int uint16 things\nproperty int16 value\n";
  const std::string index_type = double_coords ? "uint" : "int";
  out += "element face 2\nproperty list uchar " + index_type + " " + index_name + "\n";
  out += "property list uint8 float32 uv\nend_header\n";
  const float xyz[5][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {1, 1, -3}};
  for (int v = 0; v < 5; ++v) {
    const auto coordinate = [&](int axis) {
      if (double_coords) put<double>(out, xyz[v][axis], big_endian);
      else put<float>(out, xyz[v][axis], big_endian);
    };
    coordinate(0);
    coordinate(1);
    put<std::uint8_t>(out, 200, big_endian);
    put<std::uint8_t>(out, static_cast<std::uint8_t>(v), big_endian);  // list of v shorts
    for (int k = 0; k < v; ++k) put<std::int16_t>(out, -1, big_endian);
    coordinate(2);
  }
  for (int s = 0; s < 2; ++s) {
    put<std::int32_t>(out, 3, big_endian);
    for (int k = 0; k < 3; ++k) put<std::uint16_t>(out, 60000, big_endian);
    put<std::int16_t>(out, -5, big_endian);
  }
  const std::vector<std::vector<std::uint32_t>> faces = {{0, 1, 2, 3}, {1, 2, 4}};
  for (const auto& face : faces) {
    put<std::uint8_t>(out, static_cast<std::uint8_t>(face.size()), big_endian);
    for (std::uint32_t i : face) {
      if (double_coords) put<std::uint32_t>(out, i, big_endian);
      else put<std::int32_t>(out, static_cast<std::int32_t>(i), big_endian);
    }
    put<std::uint8_t>(out, 2, big_endian);
    put<float>(out, 0.25f, big_endian);
    put<float>(out, 0.75f, big_endian);
  }
  return out;
}

void expect_binary_mesh(const TriangleMesh& mesh, const MeshLoadReport& report) {
  ASSERT_EQ(mesh.positions.size(), 5u);
  EXPECT_EQ(mesh.positions[2], vec3(2, 2, 0));
  EXPECT_EQ(mesh.positions[4], vec3(1, 1, -3));
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], glm::uvec3(1, 2, 4));
  EXPECT_EQ(report.faces_in_file, 2u);
  EXPECT_EQ(report.triangles_loaded, 3u);
  EXPECT_EQ(report.degenerate_dropped, 0u);
}

TEST_F(MeshIoPly, BinaryLittleEndianFloatCoordinatesIntIndices) {
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("le.ply", binary_ply(false, false, "vertex_indices")), &report);
  expect_binary_mesh(mesh, report);
}

TEST_F(MeshIoPly, BinaryBigEndianDoubleCoordinatesUintIndices) {
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("be.ply", binary_ply(true, true, "vertex_index")), &report);
  expect_binary_mesh(mesh, report);
}

TEST_F(MeshIoPly, PentagonIsFanTriangulated) {
  const char* text =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n2 0 0\n3 1 0\n1 3 0\n-1 1 0\n5 0 1 2 3 4\n";
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("pentagon.ply", text), &report);
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], glm::uvec3(0, 3, 4));
  EXPECT_EQ(report.faces_in_file, 1u);
}

TEST_F(MeshIoPly, DegenerateTrianglesAreDroppedAndCounted) {
  // Face 1 repeats a vertex, face 2 is collinear, face 3 is a quad whose
  // second fan triangle has zero area; faces 0 and 3's first triangle stay.
  const char* text =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n2 0 0\n0 2 0\n"
      "3 0 1 2\n3 0 1 1\n3 0 1 3\n4 0 1 2 2\n";
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("degenerate.ply", text), &report);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], glm::uvec3(0, 1, 2));
  EXPECT_EQ(report.faces_in_file, 4u);
  EXPECT_EQ(report.triangles_loaded, 2u);
  EXPECT_EQ(report.degenerate_dropped, 3u);
}

const char* const kObjTwoObjects =
    "# two objects\n"
    "mtllib missing.mtl\n"
    "o first\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
    "vn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "usemtl red\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
    "o second\n"
    "v 0 0 5\nv 1 0 5\nv 0 1 5\n"
    "f 5 6 7\n"
    "f -3 -2 -1\n";

TEST_F(MeshIoObj, QuadAndTwoObjectsAreConcatenated) {
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write("two.obj", kObjTwoObjects), &report);
  ASSERT_EQ(mesh.positions.size(), 7u);
  EXPECT_EQ(mesh.positions[5], vec3(1, 0, 5));
  ASSERT_EQ(mesh.triangles.size(), 4u);
  for (int t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k) EXPECT_LT(mesh.triangles[t][k], 4u);
  EXPECT_EQ(mesh.triangles[2], glm::uvec3(4, 5, 6));
  EXPECT_EQ(mesh.triangles[3], glm::uvec3(4, 5, 6));
  EXPECT_EQ(report.faces_in_file, 4u);  // tinyobj's triangulated faces
  EXPECT_EQ(report.triangles_loaded, 4u);
  EXPECT_EQ(report.degenerate_dropped, 0u);
}

TEST_F(MeshIoObj, DegenerateTriangleDropped) {
  MeshLoadReport report;
  const char* text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 3\n";
  const TriangleMesh mesh = load_mesh(write("degenerate.OBJ", text), &report);
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(report.faces_in_file, 3u);
  EXPECT_EQ(report.degenerate_dropped, 2u);
}

TEST_F(MeshIoGzip, GzipPlyMatchesPlain) {
  MeshLoadReport plain_report, gz_report;
  const TriangleMesh plain = load_mesh(write("square.ply", kAsciiPlyWithExtras), &plain_report);
  const TriangleMesh gz = load_mesh(write_gz("square.PLY.GZ", kAsciiPlyWithExtras), &gz_report);
  EXPECT_EQ(gz.positions, plain.positions);
  EXPECT_EQ(gz.triangles, plain.triangles);
  EXPECT_EQ(gz_report.faces_in_file, 2u);
  const TriangleMesh binary = load_mesh(write_gz("be.ply.gz", binary_ply(true, false, "vertex_indices")));
  EXPECT_EQ(binary.triangles.size(), 3u);
}

TEST_F(MeshIoGzip, GzipObj) {
  MeshLoadReport report;
  const TriangleMesh mesh = load_mesh(write_gz("two.obj.gz", kObjTwoObjects), &report);
  EXPECT_EQ(mesh.positions.size(), 7u);
  EXPECT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(report.faces_in_file, 4u);
}

TEST_F(MeshIoGzip, ReadFileMaybeGzReadsPlainAndCompressed) {
  std::string big;
  for (int i = 0; i < 100000; ++i) big += std::to_string(i) + "\n";  // larger than one read chunk
  const std::vector<char> expected(big.begin(), big.end());
  EXPECT_EQ(read_file_maybe_gz(write("plain.txt", big)), expected);
  EXPECT_EQ(read_file_maybe_gz(write_gz("packed.txt.gz", big)), expected);
  EXPECT_TRUE(read_file_maybe_gz(write("empty.txt", "")).empty());
}

TEST_F(MeshIoErrors, FileProblems) {
  expect_input_error(dir_ / "missing.ply", {"cannot open", "No such file or directory"});
  expect_input_error(dir_ / "missing.obj.gz", {"cannot open", "No such file or directory"});
  fs::create_directories(dir_ / "folder.ply");
  expect_input_error(dir_ / "folder.ply", {"a mesh must be a regular file, not a folder"});

  std::string packed;
  {
    const fs::path path = write_gz("scratch.gz", kAsciiPlyWithExtras);
    std::ifstream in(path, std::ios::binary);
    packed.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path truncated = write("truncated.ply.gz", packed.substr(0, packed.size() / 2));
  expect_input_error(truncated, {"corrupt gzip data: unexpected end of file"});
  try {
    read_file_maybe_gz(truncated);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), truncated.string() + ": corrupt gzip data: unexpected end of file");
  }
  std::string garbled = packed;
  for (std::size_t i = 12; i < garbled.size() - 8; ++i) garbled[i] = static_cast<char>(garbled[i] ^ 0x5a);
  expect_error("garbled.ply.gz", garbled, {"corrupt gzip data"});
}

TEST_F(MeshIoErrors, UnknownExtension) {
  expect_error("mesh.xyz", "whatever", {"unknown mesh format '.xyz'", "expected .obj, .ply"});
  expect_error("mesh.stl.gz", "whatever", {"unknown mesh format '.stl'"});
  expect_error("mesh", "whatever", {"unknown mesh format ''"});
}

// A valid small ASCII PLY header with `line` spliced in as line 3.
std::string header_with(const std::string& line) {
  return "ply\nformat ascii 1.0\n" + line +
         "\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
         "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
}

TEST_F(MeshIoErrors, PlyMalformedHeader) {
  expect_error("a.ply", "plx\nformat ascii 1.0\nend_header\n", {"not a PLY file"});
  expect_error("b.ply", header_with("property flaot q"), {":3: ", "PLY property before any element"});
  expect_error("c.ply", header_with("element extra 1\nproperty flaot q"),
               {":4: ", "unknown PLY property type 'flaot'"});
  expect_error("d.ply", header_with("element extra 1\nproperty list uchar q"), {":4: ", "malformed PLY property line"});
  expect_error("e.ply", header_with("element extra lots"), {":3: ", "malformed PLY element line"});
  expect_error("f.ply", header_with("elephant 3"), {":3: ", "unknown PLY header keyword 'elephant'"});
  expect_error("g.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", {":2: ", "unsupported PLY format"});
  expect_error("h.ply", "ply\nformat ascii 2.0\nend_header\n", {":2: ", "unsupported PLY format"});
  expect_error("i.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", {"truncated PLY header"});
  expect_error("j.ply", "ply\nelement vertex 0\nend_header\n", {"no format line"});
}

TEST_F(MeshIoErrors, PlyMissingVertexCoordinatesOrFaces) {
  const std::string base = "ply\nformat ascii 1.0\n";
  const std::string xyz = "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 0\nproperty list uchar int vertex_indices\n";
  expect_error("a.ply", base + "element vertex 1\nproperty float x\nproperty float z\n" + faces + "end_header\n",
               {"no scalar 'y' property"});
  expect_error("b.ply", base + xyz + "end_header\n0 0 0\n", {"no 'face' element"});
  expect_error("c.ply", base + faces + "end_header\n", {"no 'vertex' element"});
  expect_error("d.ply", base + xyz + "element face 0\nproperty list uchar int corners\nend_header\n0 0 0\n",
               {"no 'vertex_indices' list property"});
}

TEST_F(MeshIoErrors, PlyTruncated) {
  const std::string text = header_with("comment fine");
  expect_error("faces.ply", text.substr(0, text.size() - 4), {"truncated: expected 1 faces, found 0"});
  expect_error("vertices.ply", text.substr(0, text.find("0 1 0")), {"the header declares 3 vertices, more than the 12 bytes after it can hold"});
  const std::string binary = binary_ply(false, false, "vertex_indices");
  expect_error("binary.ply", binary.substr(0, binary.size() - 5), {"truncated: expected 2 faces, found 1"});
  // 90 bytes of vertices, then 12 bytes per 'skipme' element.
  expect_error("skipped.ply", binary.substr(0, binary.find("end_header") + 11 + 105),
               {"truncated: expected 2 'skipme' elements, found 1"});
}

TEST_F(MeshIoErrors, PlyBadBodyValues) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string faces = "3 0 1 2\n3 0 1 3\n";
  expect_error("nan.ply", head + "0 0 0\n1 0 0\nnan 0 1\n0 0 1\n" + faces,
               {"vertex 2 has a non-finite coordinate (nan, 0, 1)"});
  expect_error("inf.ply", head + "0 0 0\n1 0 0\n0 1 0\n0 -inf 1\n" + faces,
               {"vertex 3 has a non-finite coordinate (0, -inf, 1)"});
  expect_error("range.ply", head + verts + "3 0 1 2\n3 0 1 7\n",
               {"face 1 refers to vertex 7 but the mesh has 4 vertices"});
  expect_error("negative.ply", head + verts + "3 0 -1 2\n3 0 1 3\n",
               {"face 0 refers to vertex -1 but the mesh has 4 vertices"});
  expect_error("two.ply", head + verts + "3 0 1 2\n2 0 1\n", {"face 1 has 2 vertices"});
  // Line 12 is the third body line.
  expect_error("number.ply", head + "0 0 0\n1 0 0\n0 1x 0\n0 0 1\n" + faces, {":12: ", "malformed number '1x'"});
  expect_error("overflow.ply", head + "0 0 0\n1 0 0\n0 1e999 0\n0 0 1\n" + faces,
               {":12: ", "number '1e999' is out of range"});
  // An underflow is just 0.
  MeshLoadReport report;
  EXPECT_EQ(load_mesh(write("tiny.ply", head + "0 0 1e-999\n1 0 0\n0 1 0\n0 0 1\n" + faces), &report).positions[0],
            vec3(0.0f));
  expect_error("fraction.ply", head + verts + "3 0 1 2.5\n3 0 1 3\n", {"face 0 has an invalid vertex index"});
  expect_error("length.ply", head + verts + "-3 0 1 2\n3 0 1 3\n", {"invalid list length"});
  expect_error("flat.ply", head + "0 0 0\n1 0 0\n2 0 0\n3 0 0\n3 0 1 2\n3 1 1 3\n",
               {"no usable triangles (2 degenerate dropped)"});
}

// ASCII PLY holds one element per line: a value too many or too few is
// reported at its line and element, not where the shifted values end up
// (once "face 0 has 0 vertices" for an extra value on a vertex line).
TEST_F(MeshIoErrors, PlyAsciiLineWithAValueTooManyOrTooFew) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string faces = "3 0 1 2\n3 0 2 3\n";
  // Line 10 is the first body line.
  expect_error("vertex_extra.ply", head + "0 0 0\n1 0 0 7\n1 1 0\n0 1 0\n" + faces,
               {":11: ", "vertex 1 has more values than the header gives it (x, y, z): the first extra is '7'"});
  expect_error("vertex_short.ply", head + "0 0 0\n1 0\n1 1 0\n0 1 0\n" + faces,
               {":11: ", "vertex 1 ends after 2 values, inside its property 'z'"});
  expect_error("face_extra.ply", head + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 3\n3 0 2 3\n",
               {":14: ", "face 0 has more values than the header gives it (list vertex_indices): the first extra is '3'"});
  expect_error("face_short.ply", head + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1\n3 0 2 3\n",
               {":14: ", "face 0 ends after 3 values, inside its list 'vertex_indices'"});
  expect_error("after.ply", head + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n" + faces + "\n3 1 2 3\n",
               {":17: ", "'3' after the last element the header declares"});
  // Blank lines, "\r\n" and spaces around the values are fine; so is a last line without its '\n'.
  MeshLoadReport report;
  EXPECT_EQ(load_mesh(write("spaced.ply", head + "\n 0 0 0 \r\n\n1\t0 0\r\n1 1 0\n0 1 0\n\n3 0 1 2\n3 0 2 3"), &report)
                .triangles.size(),
            2u);
}

TEST_F(MeshIoErrors, BinaryPlyNonFiniteCoordinate) {
  std::string binary = binary_ply(true, true, "vertex_indices");
  const std::size_t body = binary.find("end_header\n") + 11;
  std::string nan_bytes;
  put<double>(nan_bytes, std::numeric_limits<double>::quiet_NaN(), true);
  binary.replace(body, 8, nan_bytes);  // x of vertex 0
  expect_error("nan.ply", binary, {"vertex 0 has a non-finite coordinate (nan, 0, 0)"});
}

// OBJ messages number faces and vertices from 1, like the file does.
TEST_F(MeshIoErrors, ObjProblems) {
  const std::string verts = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  expect_error("zero.obj", verts + "f 0 1 2\n", {"zero.obj:5:", "face token '0'", "not a non-zero integer", "valid: 1..4 or -4..-1"});
  expect_error("range.obj", verts + "f 1 2 3\nf 1 2 9\n",
               {"range.obj:6:", "face token '9'", "vertex index 9 is beyond the 4 vertex(s)"});
  expect_error("negative.obj", verts + "f 1 2 -9\n", {"negative.obj:5:", "face token '-9'", "vertex index -9 counts back past the 4 vertex(s)"});
  // tinyobj drops a quad with a bad index instead of failing; we still report it.
  expect_error("quad.obj", verts + "f 1 2 3\nf 1 2 3 9\n", {"quad.obj:6:", "face token '9'", "beyond the 4 vertex(s)"});
  // 1e39 overflows float.
  expect_error("huge.obj", verts + "v 1e39 0 0\nf 1 2 3\n", {"vertex 5 has a non-finite coordinate (inf, 0, 0)"});
  expect_error("line.obj", verts + "f 1 2\n", {"fewer than 3 vertices"});
}

// A file without faces says so, rather than "no usable triangles".
TEST_F(MeshIoErrors, NoFaces) {
  expect_error("empty.obj", "# nothing\n", {"empty.obj: no faces"});
  expect_error("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", {"points.obj: no faces"});
  expect_error("none.ply",
               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
               {"none.ply: no faces"});
}

// tinyobj reads "nan", "inf" and garbage coordinates as 0, so mesh_io checks
// the vertex lines itself and names the line and the vertex (from 1).
TEST_F(MeshIoErrors, ObjNonFiniteAndMalformedCoordinates) {
  const std::string face = "f 1 2 3\n";
  expect_error("nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\n" + face,
               {"nan.obj:2: vertex 2 has a non-finite coordinate (1, nan, 0)"});
  expect_error("inf.obj", "v inf 0 0\nv 1 0 0\nv 0 1 0\n" + face,
               {"inf.obj:1: vertex 1 has a non-finite coordinate (inf, 0, 0)"});
  expect_error("ninf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 -Infinity\n" + face,
               {"ninf.obj:3: vertex 3 has a non-finite coordinate (0, 1, -Infinity)"});
  // 1e999 overflows even a double.
  expect_error("huge.obj", "v 0 0 0\nv 1 1e999 0\nv 0 1 0\n" + face,
               {"huge.obj:2: vertex 2 has a non-finite coordinate (1, 1e999, 0)"});
  expect_error("abc.obj", "v 0 0 0\nv 1 abc 0\nv 0 1 0\n" + face, {"abc.obj:2: vertex 2: malformed number 'abc'"});
  expect_error("suffix.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0.5x\n" + face,
               {"suffix.obj:3: vertex 3: malformed number '0.5x'"});
  expect_error("comma.obj", "v 0 0 0\nv 1,5 0 0\nv 0 1 0\n" + face, {"comma.obj:2: vertex 2: malformed number '1,5'"});
  expect_error("short.obj", "v 0 0 0\nv 1 0\nv 0 1 0\n" + face, {"short.obj:2: vertex 2 has 2 coordinates (3 needed)"});
  // Only 'v' lines count as vertices; lines count from 1, indented or not.
  expect_error("mixed.obj", "# comment\nvn 0 0 1\nv 0 0 0\n  v 1 0 0\nvt 0.5 0\n\tv 0 1 NaN\r\n" + face,
               {"mixed.obj:6: vertex 3 has a non-finite coordinate (0, 1, NaN)"});
  // Normals and texture coordinates are counted and checked as vertices are.
  expect_error("vt.obj", "v 0 0 0\nv 1 0 0\nvt 0 0\nvt nan 0\nv 0 1 0\n" + face,
               {"vt.obj:4: texture coordinate 2 has a non-finite coordinate (nan, 0)"});
  expect_error("vn.obj", "vn 0 0 1\nv 0 0 0\nv 1 0 0\nvn 0 inf 1\nv 0 1 0\n" + face,
               {"vn.obj:4: normal 2 has a non-finite coordinate (0, inf, 1)"});
  // A lone "\r" ends a line too (for tinyobj as well).
  expect_error("cr.obj", "v 0 0 0\r\rv 1 0 0\rv 0 1 x\r" + face, {"cr.obj:4: vertex 3: malformed number 'x'"});
}

TEST_F(MeshIoObj, VertexCheckAcceptsEveryNumberForm) {
  // Signs, exponents, an underflow to 0, tabs, CRLF, a w and vertex colours.
  const TriangleMesh mesh =
      load_mesh(write("forms.obj", "v +0 -0.0 1e-999\r\nv\t1.\t0 0 1\nv .0 1E0 0 1 0.5 0.25\n"
                                   "vt 0 0\nf 1 2 3\n"));
  ASSERT_EQ(mesh.positions.size(), 3u);
  EXPECT_EQ(mesh.positions[0], vec3(0.0f));
  EXPECT_EQ(mesh.positions[1], vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(mesh.positions[2], vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(mesh.triangles.size(), 1u);
}

// Binary PLY with normals (double, big-endian) and texture coordinates
// (float, as texture_u / texture_v): read through the same decoder as the
// positions.
TEST_F(MeshIoPly, BinaryNormalsAndTextureCoordinates) {
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big-endian" : "little-endian");
    std::string out = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") + " 1.0\n";
    out += "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
           "property double nx\nproperty double ny\nproperty double nz\n"
           "property float texture_u\nproperty float texture_v\n"
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const float p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const double n[3][3] = {{0, 0, 2}, {0, 0.6, 0.8}, {1, 0, 1}};
    for (int v = 0; v < 3; ++v) {
      for (int k = 0; k < 3; ++k) put<float>(out, p[v][k], big);
      for (int k = 0; k < 3; ++k) put<double>(out, n[v][k], big);
      put<float>(out, 0.25f * static_cast<float>(v), big);
      put<float>(out, 1.0f - 0.25f * static_cast<float>(v), big);
    }
    put<std::uint8_t>(out, 3, big);
    for (std::int32_t i : {0, 1, 2}) put<std::int32_t>(out, i, big);
    const TriangleMesh mesh = load_mesh(write("bn.ply", out));
    ASSERT_EQ(mesh.normals.size(), 3u);
    ASSERT_EQ(mesh.uvs.size(), 3u);
    EXPECT_EQ(mesh.normals[0], vec3(0, 0, 1));
    EXPECT_NEAR(mesh.normals[1].y, 0.6f, 1e-7f);
    EXPECT_NEAR(mesh.normals[2].x, std::sqrt(0.5f), 1e-7f);
    EXPECT_EQ(mesh.uvs[2], vec2(0.5f, 0.5f));
  }
}

}  // namespace
}  // namespace pathlab
