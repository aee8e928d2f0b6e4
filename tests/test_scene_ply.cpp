// PLY meshes (host/scene/ply_mesh.cpp) and pbrt-v4's Shape "plymesh": small PLY files written
// here in each encoding, read back value for value; a plymesh scene against the same mesh as a
// trianglemesh; and the one-line errors of broken files.
#include "scene/pbrt_reader.h"
#include "scene/ply_mesh.h"
#include "scene/scene.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace canopy;
using canopy::detail::load_ply_mesh;
using canopy::detail::PlyMesh;

namespace {

namespace fs = std::filesystem;

enum class Enc { Ascii, LittleEndian, BigEndian };

// The content of a PLY file: float vertex properties (one row of values per vertex) and faces as
// "list uchar int vertex_indices".
struct Ply {
  std::vector<std::string> props;
  std::vector<std::vector<float>> rows;
  std::vector<std::vector<int32_t>> faces;
};

template <class T> void put(std::string& out, T v, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big) std::reverse(b, b + sizeof(T));
  out.append(b, sizeof(T));
}

std::string ply_bytes(const Ply& p, Enc enc) {
  std::ostringstream h;
  h << "ply\nformat "
    << (enc == Enc::Ascii          ? "ascii"
        : enc == Enc::LittleEndian ? "binary_little_endian"
                                   : "binary_big_endian")
    << " 1.0\ncomment written by test_scene_ply\nelement vertex " << p.rows.size() << "\n";
  for (const std::string& n : p.props)
    h << "property float " << n << "\n";
  h << "element face " << p.faces.size() << "\nproperty list uchar int vertex_indices\n"
    << "end_header\n";
  std::string out = h.str();
  if (enc == Enc::Ascii) {
    std::ostringstream b;
    b.precision(9); // round-trips a float
    for (const auto& r : p.rows) {
      for (float v : r)
        b << v << ' ';
      b << "\n";
    }
    for (const auto& f : p.faces) {
      b << f.size();
      for (int32_t i : f)
        b << ' ' << i;
      b << "\n";
    }
    return out + b.str();
  }
  const bool big = enc == Enc::BigEndian;
  for (const auto& r : p.rows)
    for (float v : r)
      put(out, v, big);
  for (const auto& f : p.faces) {
    put(out, uint8_t(f.size()), big);
    for (int32_t i : f)
      put(out, i, big);
  }
  return out;
}

// A fresh directory for one test.
fs::path temp_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path d =
      fs::temp_directory_path() / ("canopy_ply_" + std::to_string(::getpid()) + "_" + info->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

void write(const fs::path& f, const std::string& bytes) {
  fs::create_directories(f.parent_path());
  std::ofstream(f, std::ios::binary) << bytes;
}

void write_gz(const fs::path& f, const std::string& bytes) {
  gzFile g = gzopen(f.c_str(), "wb");
  ASSERT_NE(g, nullptr);
  ASSERT_EQ(gzwrite(g, bytes.data(), unsigned(bytes.size())), int(bytes.size()));
  ASSERT_EQ(gzclose(g), Z_OK);
}

// Values whose bytes differ (a byte-order mistake changes them) and that are not exact in
// decimal (an ASCII reader must round them back to the same float).
const Ply kQuadAndTriangle = {{"x", "y", "z", "nx", "ny", "nz", "u", "v"},
                              {{0.1f, -2.25f, 3.0f, 0, 0, 1, 0.125f, 0.7f},
                               {1.3f, -2.25f, 3.0f, 0, 0.6f, 0.8f, 0.9f, 0.7f},
                               {1.3f, -1.1f, 3.0f, 0, 0, 1, 0.9f, 0.2f},
                               {0.1f, -1.1f, 3.0f, 0, 0, 1, 0.125f, 0.2f},
                               {5.5f, 6.75f, -7.0f, 1, 0, 0, 0.5f, 0.5f}},
                              {{0, 1, 2, 3}, {1, 4, 2}}};

// The triangles of m, each rotated to start at its smallest index (a triangulation may start a
// polygon's fan anywhere), sorted.
std::vector<std::array<uint32_t, 3>> triangles(const std::vector<uint32_t>& idx) {
  std::vector<std::array<uint32_t, 3>> t;
  for (size_t i = 0; i + 2 < idx.size(); i += 3) {
    std::array<uint32_t, 3> a{idx[i], idx[i + 1], idx[i + 2]};
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    t.push_back(a);
  }
  std::sort(t.begin(), t.end());
  return t;
}

// The quad (0 1 2 3) as two triangles with its winding, either diagonal, and the triangle.
void expect_quad_and_triangle(const PlyMesh& m) {
  auto t = triangles(m.indices);
  using T = std::vector<std::array<uint32_t, 3>>;
  T diag02 = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}}, diag13 = {{0, 1, 3}, {1, 2, 3}, {1, 4, 2}};
  std::sort(diag02.begin(), diag02.end());
  std::sort(diag13.begin(), diag13.end());
  EXPECT_TRUE(t == diag02 || t == diag13);
  EXPECT_EQ(m.indices.size(), 9u);
}

void expect_rows(const PlyMesh& m, const Ply& p, bool normals, bool uv) {
  ASSERT_EQ(m.positions.size(), p.rows.size());
  ASSERT_EQ(m.normals.size(), normals ? p.rows.size() : 0u);
  ASSERT_EQ(m.uv.size(), uv ? p.rows.size() : 0u);
  for (size_t i = 0; i < p.rows.size(); ++i) {
    const auto& r = p.rows[i];
    EXPECT_EQ(m.positions[i].x, r[0]) << i;
    EXPECT_EQ(m.positions[i].y, r[1]) << i;
    EXPECT_EQ(m.positions[i].z, r[2]) << i;
    if (normals) {
      EXPECT_EQ(m.normals[i].x, r[3]) << i;
      EXPECT_EQ(m.normals[i].y, r[4]) << i;
      EXPECT_EQ(m.normals[i].z, r[5]) << i;
    }
    if (uv) {
      EXPECT_EQ(m.uv[i].x, r[r.size() - 2]) << i;
      EXPECT_EQ(m.uv[i].y, r[r.size() - 1]) << i;
    }
  }
}

PlyMesh load(const fs::path& f) {
  return load_ply_mesh(f, "p: ");
}

std::string error_of(const fs::path& f) {
  try {
    load(f);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

Ply without(const Ply& p, size_t first, size_t n) {
  Ply q = p;
  q.props.erase(q.props.begin() + ptrdiff_t(first), q.props.begin() + ptrdiff_t(first + n));
  for (auto& r : q.rows)
    r.erase(r.begin() + ptrdiff_t(first), r.begin() + ptrdiff_t(first + n));
  return q;
}

} // namespace

// ------------------------------------------------------------------------------------ loader

TEST(ScenePly, EachEncodingReadsTheSameValuesAndTriangulatesTheQuad) {
  fs::path d = temp_dir();
  for (Enc enc : {Enc::Ascii, Enc::LittleEndian, Enc::BigEndian}) {
    SCOPED_TRACE(int(enc));
    write(d / "m.ply", ply_bytes(kQuadAndTriangle, enc));
    PlyMesh m = load(d / "m.ply");
    expect_rows(m, kQuadAndTriangle, true, true);
    expect_quad_and_triangle(m);
    EXPECT_EQ(m.skipped_faces, 0u);
  }
}

TEST(ScenePly, GzippedFileReadsTheSame) {
  fs::path d = temp_dir();
  write_gz(d / "m.ply.gz", ply_bytes(kQuadAndTriangle, Enc::BigEndian));
  PlyMesh m = load(d / "m.ply.gz");
  expect_rows(m, kQuadAndTriangle, true, true);
  expect_quad_and_triangle(m);
}

// Assimp 5.2 skips whitespace after end_header even before a binary body, so a body starting
// with the bytes '\n', '\r', ' ' or '\t' was read shifted: crown/geometry/mesh_00728.ply of the
// pbrt-v4 scenes (first byte 0x0a) aborted the process in Assimp's triangulation.
TEST(ScenePly, BinaryBodyStartingWithWhitespaceBytesIsReadExactly) {
  fs::path d = temp_dir();
  for (Enc enc : {Enc::LittleEndian, Enc::BigEndian}) {
    SCOPED_TRACE(int(enc));
    Ply p = kQuadAndTriangle;
    // Written first: little-endian 0a 0d 20 3f (x = 0.625...), big-endian 20 0a 0d 09.
    const uint32_t bits = enc == Enc::LittleEndian ? 0x3f200d0au : 0x200a0d09u;
    std::memcpy(&p.rows[0][0], &bits, sizeof bits);
    const std::string bytes = ply_bytes(p, enc);
    ASSERT_EQ(bytes[bytes.find("end_header\n") + 11], enc == Enc::LittleEndian ? '\n' : ' ');
    write(d / "m.ply", bytes);
    PlyMesh m = load(d / "m.ply");
    expect_rows(m, p, true, true);
    expect_quad_and_triangle(m);
    // Both header rewrites at once: a comment line among the vertex properties (removed) and the
    // pad property (inserted after the element line, before that comment).
    std::string commented = bytes;
    const size_t prop = commented.find("property", commented.find("element vertex"));
    commented.insert(prop, "comment between the element and its first property\n");
    const size_t second = commented.find("property", commented.find("property", prop) + 8);
    commented.insert(second, "obj_info among the properties\n");
    write(d / "c.ply", commented);
    PlyMesh c = load(d / "c.ply");
    expect_rows(c, p, true, true);
    expect_quad_and_triangle(c);
  }
}

TEST(ScenePly, NormalsAndUvAreOptionalAndUvHasPbrtsFourNames) {
  fs::path d = temp_dir();
  const Ply bare = without(without(kQuadAndTriangle, 6, 2), 3, 3);
  write(d / "bare.ply", ply_bytes(bare, Enc::LittleEndian));
  PlyMesh m = load(d / "bare.ply");
  expect_rows(m, bare, false, false);
  expect_quad_and_triangle(m);

  const std::pair<const char*, const char*> names[] = {
      {"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};
  for (auto [u, v] : names) {
    SCOPED_TRACE(u);
    Ply p = without(kQuadAndTriangle, 3, 3); // positions and uv
    p.props[3] = u;
    p.props[4] = v;
    for (Enc enc : {Enc::Ascii, Enc::LittleEndian}) {
      write(d / "uv.ply", ply_bytes(p, enc));
      PlyMesh q = load(d / "uv.ply");
      expect_rows(q, p, false, true);
    }
  }
}

TEST(ScenePly, FacesOfFewerThanThreeVerticesAreCountedNotRead) {
  fs::path d = temp_dir();
  Ply p = kQuadAndTriangle;
  p.faces.push_back({0, 4});
  write(d / "m.ply", ply_bytes(p, Enc::Ascii));
  PlyMesh m = load(d / "m.ply");
  expect_quad_and_triangle(m);
  EXPECT_EQ(m.skipped_faces, 1u);
}

TEST(ScenePly, BrokenFilesAreOneLineErrorsAfterThePrefix) {
  fs::path d = temp_dir();
  const std::string le = ply_bytes(kQuadAndTriangle, Enc::LittleEndian);
  const std::string be = ply_bytes(kQuadAndTriangle, Enc::BigEndian);
  const std::string ascii = ply_bytes(kQuadAndTriangle, Enc::Ascii);
  const size_t body = le.find("end_header\n") + 11, ascii_body = ascii.find("end_header\n") + 11;
  const size_t vertex_bytes = 5 * 8 * 4;
  struct Case {
    std::string name, bytes, want;
  };
  Ply oob = kQuadAndTriangle;
  oob.faces[1][1] = 5;
  Ply negative = kQuadAndTriangle;
  negative.faces[1][1] = -1;
  const Case cases[] = {
      {"cut_in_vertices.ply", le.substr(0, body + 50), "truncated: the file ends in vertex 2 of 5"},
      {"cut_in_face_count.ply", le.substr(0, body + vertex_bytes + 17),
       "truncated: the file ends in face 2 of 2"},
      {"cut_in_face.ply", be.substr(0, be.size() - 1), "truncated: the file ends in face 2 of 2"},
      {"cut_in_header.ply", le.substr(0, 40), "not a PLY file or truncated header (no end_header)"},
      {"cut_ascii.ply", ascii.substr(0, ascii.rfind("3 1")),
       "truncated: the file ends in face 2 of 2"},
      {"garbage.ply", std::string("\x7f\x45LF\x02\x01 garbage\n\x00\x01", 17),
       "not a PLY file (it does not start with \"ply\")"},
      {"empty.ply", "", "not a PLY file or truncated header (no end_header)"},
      {"bad_number.ply",
       ascii.substr(0, ascii_body) + "0.1 x 3" + ascii.substr(ascii.find('\n', ascii_body)),
       "line 16: vertex 1 of 5: 'x' is not a number"},
      {"index_out_of_range.ply", ply_bytes(oob, Enc::LittleEndian),
       "face 2 of 2: the vertex index 5 is out of range [0, 5)"},
      {"negative_index.ply", ply_bytes(negative, Enc::Ascii),
       "line 22: face 2 of 2: the vertex index -1 is out of range [0, 5)"},
      {"long_face.ply", ascii.substr(0, ascii.rfind("3 1")) + "2000 1 4 2\n",
       "line 22: face 2 of 2: list \"vertex_indices\" has the length '2000'"},
      {"not_gzip.ply.gz", le, "not a gzip file (the name ends in .gz)"},
  };
  for (const Case& c : cases) {
    write(d / c.name, c.bytes);
    std::string e = error_of(d / c.name);
    EXPECT_EQ(e.rfind("p: " + c.want, 0), 0u) << c.name << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << c.name;
  }
  // A gzip stream cut short.
  write_gz(d / "cut.ply.gz", le);
  std::ifstream in(d / "cut.ply.gz", std::ios::binary);
  std::string gz((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write(d / "cut.ply.gz", gz.substr(0, gz.size() / 2));
  EXPECT_EQ(error_of(d / "cut.ply.gz"), "p: truncated gzip data");
  EXPECT_EQ(error_of(d / "missing.ply"), "p: cannot open file");
}

// Face indices are checked before Assimp reads the file: its triangulation reads a polygon's
// vertices by index, so an index far out of range in a quad crashed it (SIGSEGV; found by the
// fuzzer: a binary file with bytes deleted in its vertices, whose faces then read garbage).
TEST(ScenePly, OutOfRangeIndicesOfPolygonsAreErrorsBeforeAssimp) {
  fs::path d = temp_dir();
  for (Enc enc : {Enc::Ascii, Enc::LittleEndian, Enc::BigEndian})
    for (int32_t bad : {100000000, -100000000, 5}) {
      Ply p = kQuadAndTriangle;
      ASSERT_EQ(p.faces[0].size(), 4u);
      p.faces[0][2] = bad;
      write(d / "q.ply", ply_bytes(p, enc));
      std::string e = error_of(d / "q.ply");
      EXPECT_NE(e.find("face 1 of 2: the vertex index " + std::to_string(bad) +
                       " is out of range [0, 5)"),
                std::string::npos)
          << e;
    }
  // A float index list: 1e999 (out of the double range) and NaN are out of range too.
  for (const char* bad : {"1e999", "nan", "-0.5e10"}) {
    std::string a = ply_bytes(kQuadAndTriangle, Enc::Ascii);
    a.replace(a.find("list uchar int"), 14, "list uchar float");
    a.replace(a.rfind("4 0 1 2 3"), 9, std::string("4 0 1 ") + bad + " 3");
    write(d / "f.ply", a);
    std::string e = error_of(d / "f.ply");
    EXPECT_NE(e.find(std::string("face 1 of 2: the vertex index ") + bad + " is out of range"),
              std::string::npos)
        << e;
  }
  // A face without vertices: Assimp's triangulation aborted on it (an assertion; found by the
  // fuzzer: an ASCII face line "0").
  for (Enc enc : {Enc::Ascii, Enc::LittleEndian, Enc::BigEndian}) {
    Ply p = kQuadAndTriangle;
    p.faces.push_back({});
    p.faces.push_back({0, 1, 2});
    write(d / "e.ply", ply_bytes(p, enc));
    std::string e = error_of(d / "e.ply");
    EXPECT_NE(e.find("face 3 of 4: a face without vertices"), std::string::npos) << e;
  }
  // The fuzzer's reproduction: a polygon whose count and indices are vertex bytes.
  Ply shifted = kQuadAndTriangle;
  shifted.faces[0] = {0, 1, 2, 3, 4, 0x3e99999a};
  write(d / "s.ply", ply_bytes(shifted, Enc::BigEndian));
  EXPECT_NE(error_of(d / "s.ply").find("is out of range [0, 5)"), std::string::npos);
}

// A control byte in the header is an error: Assimp's header parser and Canopy's would read
// different layouts (a comment "a\0b" between two vertex properties, "end_header\r\r\n" crashed
// Assimp; found by the fuzzer).
TEST(ScenePly, AControlByteInTheHeaderIsAnError) {
  fs::path d = temp_dir();
  for (Enc enc : {Enc::Ascii, Enc::LittleEndian, Enc::BigEndian}) {
    std::string b = ply_bytes(kQuadAndTriangle, enc);
    const size_t at = b.find("property float z\n");
    b = b.substr(0, at) + std::string("comment a\0b\xff\n", 13) + b.substr(at);
    write(d / "nul.ply", b);
    EXPECT_EQ(error_of(d / "nul.ply"), "p: header line 7: a control byte (0x00)");
    // A CR before the CRLF of end_header: Assimp started the body one byte early.
    std::string crcr = ply_bytes(kQuadAndTriangle, enc);
    crcr.replace(crcr.find("end_header\n"), 11, "end_header\r\r\n");
    write(d / "crcr.ply", crcr);
    EXPECT_EQ(error_of(d / "crcr.ply"), "p: header line 15: a control byte (0x0d)");
    // CRLF lines are fine.
    const std::string lf = ply_bytes(kQuadAndTriangle, enc);
    const size_t body = lf.find("end_header\n") + 11;
    std::string crlf;
    for (size_t k = 0; k < body; ++k)
      crlf += lf[k] == '\n' ? std::string("\r\n") : std::string(1, lf[k]);
    crlf += lf.substr(body);
    write(d / "crlf.ply", crlf);
    expect_quad_and_triangle(load(d / "crlf.ply"));
  }
}

// Comment, obj_info and blank lines may be anywhere in the header (Assimp 5.2 ended an element's
// properties at one, read another layout and crashed; found by the fuzzer).
TEST(ScenePly, CommentsBetweenPropertiesAreRead) {
  fs::path d = temp_dir();
  for (Enc enc : {Enc::Ascii, Enc::LittleEndian, Enc::BigEndian}) {
    std::string b = ply_bytes(kQuadAndTriangle, enc);
    for (const char* before : {"property float z\n", "element vertex", "property float nx\n",
                               "property list", "end_header"}) {
      const size_t at = b.find(before);
      b = b.substr(0, at) + "obj_info x\ncomment y\n  \n" + b.substr(at);
    }
    write(d / "o.ply", b);
    expect_quad_and_triangle(load(d / "o.ply"));
  }
}

// Assimp's logger stays silent (no DefaultLogger is created).
TEST(ScenePly, NothingIsPrintedOnALoadOrAnError) {
  fs::path d = temp_dir();
  write(d / "m.ply", ply_bytes(kQuadAndTriangle, Enc::Ascii));
  Ply oob = kQuadAndTriangle;
  oob.faces[1][1] = 7;
  write(d / "oob.ply", ply_bytes(oob, Enc::Ascii));
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  load(d / "m.ply");
  std::string e = error_of(d / "oob.ply");
  std::string out = ::testing::internal::GetCapturedStdout();
  std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(e, "(no error)");
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

// ------------------------------------------------------------------------------- pbrt reader

namespace {

const char* kCamera = "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";

// A trianglemesh with the rows and triangle faces of p, positions and normals.
std::string trianglemesh(const Ply& p, bool normals) {
  std::ostringstream s;
  s.precision(9);
  s << "Shape \"trianglemesh\" \"point3 P\" [";
  for (const auto& r : p.rows)
    s << r[0] << ' ' << r[1] << ' ' << r[2] << ' ';
  s << "] \"integer indices\" [";
  for (const auto& f : p.faces)
    s << f[0] << ' ' << f[1] << ' ' << f[2] << ' ';
  s << "]";
  if (normals) {
    s << " \"normal N\" [";
    for (const auto& r : p.rows)
      s << r[3] << ' ' << r[4] << ' ' << r[5] << ' ';
    s << "]";
  }
  return s.str() + "\n";
}

void expect_same_geometry(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) {
    EXPECT_EQ(a.vertices[i].x, b.vertices[i].x) << i;
    EXPECT_EQ(a.vertices[i].y, b.vertices[i].y) << i;
    EXPECT_EQ(a.vertices[i].z, b.vertices[i].z) << i;
  }
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_EQ(a.triangle_material, b.triangle_material);
  EXPECT_EQ(a.triangle_light, b.triangle_light);
  EXPECT_EQ(a.triangle_normals, b.triangle_normals);
  ASSERT_EQ(a.shading_normals.size(), b.shading_normals.size());
  for (size_t i = 0; i < a.shading_normals.size(); ++i) {
    EXPECT_EQ(a.shading_normals[i].x, b.shading_normals[i].x) << i;
    EXPECT_EQ(a.shading_normals[i].y, b.shading_normals[i].y) << i;
    EXPECT_EQ(a.shading_normals[i].z, b.shading_normals[i].z) << i;
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) {
    EXPECT_EQ(a.lights[i].emission.x, b.lights[i].emission.x) << i;
    EXPECT_EQ(a.lights[i].flags, b.lights[i].flags) << i;
  }
}

} // namespace

// The same triangles as a plymesh and as a trianglemesh, under a transform, ReverseOrientation,
// a material and a two-sided area light, with and without vertex normals (which decide the
// orientation when present): the same Scene geometry.
TEST(ScenePly, PlymeshBuildsWhatTheSameTriangleMeshBuilds) {
  fs::path d = temp_dir();
  Ply tris = kQuadAndTriangle;
  tris.faces = {{0, 1, 2}, {0, 2, 3}, {1, 4, 2}};
  // The second triangle's normals point against its winding.
  for (int k : {0, 2, 3})
    tris.rows[size_t(k)][5] = -1.0f;
  const std::string state =
      "Translate 1 2 3\nRotate 30 0.3 1 0.2\nScale 2 -1 1.5\n"
      "ReverseOrientation\nMaterial \"conductor\"\n"
      "AreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"bool twosided\" true\n";
  for (bool normals : {true, false}) {
    SCOPED_TRACE(normals);
    Ply p = normals ? without(tris, 6, 2) : without(tris, 3, 5);
    write(d / "geometry" / "m.ply", ply_bytes(p, Enc::BigEndian));
    Scene ply = load_pbrt_scene_from_string(std::string(kCamera) + state +
                                                "Shape \"plymesh\" \"string filename\" "
                                                "\"geometry/m.ply\"\n",
                                            "t.pbrt", d);
    Scene tri = load_pbrt_scene_from_string(
        std::string(kCamera) + state + trianglemesh(normals ? p : tris, normals), "t.pbrt", d);
    EXPECT_EQ(ply.triangle_count(), 3u);
    EXPECT_EQ(ply.lights.size(), 3u);
    EXPECT_EQ(ply.shading_normals.empty(), !normals);
    expect_same_geometry(ply, tri);
    EXPECT_TRUE(ply.warnings.empty()) << ply.warnings[0];
  }
}

TEST(ScenePly, AFileWithoutTrianglesIsAWarning) {
  fs::path d = temp_dir();
  Ply lines = kQuadAndTriangle;
  lines.faces = {{0, 4}};
  Ply points = kQuadAndTriangle;
  points.faces.clear();
  write(d / "lines.ply", ply_bytes(lines, Enc::LittleEndian));
  write(d / "points.ply", ply_bytes(points, Enc::Ascii));
  Scene s = load_pbrt_scene_from_string(
      std::string(kCamera) + "Shape \"plymesh\" \"string filename\" \"lines.ply\"\n" +
          "Shape \"plymesh\" \"string filename\" \"points.ply\"\n",
      "t.pbrt", d);
  EXPECT_EQ(s.triangle_count(), 0u);
  const char* want[] = {
      "t.pbrt:4: Shape \"plymesh\": 1 faces of fewer than 3 vertices ignored",
      "t.pbrt:4: Shape \"plymesh\": no faces of 3 or more vertices, nothing added, ignored",
      "t.pbrt:5: Shape \"plymesh\": no faces of 3 or more vertices, nothing added, ignored"};
  ASSERT_EQ(s.warnings.size(), std::size(want));
  for (size_t i = 0; i < std::size(want); ++i)
    EXPECT_EQ(s.warnings[i], want[i]);
}

// As Include: relative to the directory of the file that holds the directive.
TEST(ScenePly, FilenameIsRelativeToTheFileThatNamesIt) {
  fs::path d = temp_dir();
  write(d / "parts" / "m.ply", ply_bytes(kQuadAndTriangle, Enc::Ascii));
  write(d / "parts" / "part.pbrt", "Shape \"plymesh\" \"string filename\" \"m.ply\"\n");
  write(d / "main.pbrt", std::string(kCamera) + "Include \"parts/part.pbrt\"\n");
  Scene s = load_scene(d / "main.pbrt");
  EXPECT_EQ(s.triangle_count(), 3u);
}

TEST(ScenePly, IgnoredParametersAreWarnedAndBrokenFilesNameTheDirective) {
  fs::path d = temp_dir();
  write(d / "m.ply", ply_bytes(kQuadAndTriangle, Enc::Ascii));
  Scene s = load_pbrt_scene_from_string(
      std::string(kCamera) + "Shape \"plymesh\" \"string filename\" \"m.ply\"\n"
                             "  \"texture displacement\" \"bumps\" \"float edgelength\" 0.5\n"
                             "  \"float alpha\" 0.5\n",
      "t.pbrt", d);
  EXPECT_EQ(s.triangle_count(), 3u);
  const char* want[] = {"t.pbrt:5: Shape \"plymesh\": \"float edgelength\" ignored",
                        "t.pbrt:6: Shape \"plymesh\": \"float alpha\" ignored",
                        "t.pbrt:5: Shape \"plymesh\": \"texture displacement\" ignored"};
  ASSERT_EQ(s.warnings.size(), std::size(want));
  for (size_t i = 0; i < std::size(want); ++i)
    EXPECT_EQ(s.warnings[i], want[i]);

  write(d / "cut.ply", ply_bytes(kQuadAndTriangle, Enc::LittleEndian).substr(0, 300));
  for (auto [file, problem] : {std::pair<std::string, std::string>{"cut.ply", "truncated: the "
                                                                              "file ends in "
                                                                              "vertex"},
                               {"none.ply", "cannot open file"}}) {
    try {
      load_pbrt_scene_from_string(std::string(kCamera) +
                                      "\nShape \"plymesh\" \"string filename\" \"" + file + "\"\n",
                                  "t.pbrt", d);
      ADD_FAILURE() << file << " loaded";
    } catch (const SceneError& e) {
      std::string start = "t.pbrt:5: Shape \"plymesh\" \"" + (d / file).string() + "\": " + problem;
      EXPECT_EQ(std::string(e.what()).rfind(start, 0), 0u) << e.what() << "\nwant: " << start;
    }
  }
}
