// PLY meshes via Assimp (Debian's libassimp, 5.2). Assimp 5.2's PLY reader trusts the file: a
// truncated binary file crashes it (it reads past the end), a truncated ASCII file or header makes
// it loop forever, and face indices past the vertex count are passed on. So the file's structure
// is checked first against its header (every element present and complete, list lengths within
// bounds, ASCII values numeric), and the indices after the import.
#include "scene/ply_mesh.h"

#include "scene/loader_internal.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <string_view>

namespace canopy::detail {

namespace {

[[noreturn]] void fail(const std::string& prefix, std::string_view msg) {
  throw SceneError(fmt::format("{}{}", prefix, msg));
}

// ------------------------------------------------------------------------------------ gzip

// The gzip members of `in`, decompressed; at most max_bytes.
std::string gunzip(const std::string& in, uint64_t max_bytes, const std::string& prefix) {
  if (in.size() < 2 || uint8_t(in[0]) != 0x1f || uint8_t(in[1]) != 0x8b)
    fail(prefix, "not a gzip file (the name ends in .gz)");
  z_stream zs{};
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) fail(prefix, "cannot start zlib");
  struct End {
    z_stream* zs;
    ~End() { inflateEnd(zs); }
  } end{&zs};
  std::string out;
  size_t in_pos = 0;
  int rc = Z_OK;
  while (true) {
    if (zs.avail_in == 0 && in_pos < in.size()) {
      size_t n = std::min<size_t>(in.size() - in_pos, size_t(1) << 30);
      zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + in_pos));
      zs.avail_in = uInt(n);
      in_pos += n;
    }
    if (out.size() >= max_bytes)
      fail(prefix, fmt::format("decompressed data is larger than {} bytes", max_bytes));
    size_t have = out.size();
    size_t chunk = std::min<size_t>(std::max<size_t>(have, size_t(1) << 16), size_t(1) << 28);
    out.resize(have + chunk);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + have);
    zs.avail_out = uInt(chunk);
    rc = inflate(&zs, Z_NO_FLUSH);
    out.resize(have + (chunk - zs.avail_out));
    if (rc == Z_STREAM_END) {
      if (zs.avail_in == 0 && in_pos == in.size()) break;
      inflateReset(&zs); // another gzip member follows (concatenated .gz files)
      continue;
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && in_pos == in.size())
      fail(prefix, "truncated gzip data");
    if (rc != Z_OK && rc != Z_BUF_ERROR)
      fail(prefix, fmt::format("corrupt gzip data ({})", zs.msg ? zs.msg : zError(rc)));
  }
  if (out.size() > max_bytes)
    fail(prefix, fmt::format("decompressed data is larger than {} bytes", max_bytes));
  return out;
}

// ------------------------------------------------------------------------- structure check

enum class Format { Ascii, BinaryLE, BinaryBE };

struct ScalarType {
  int size = 0; // bytes in a binary file
  bool integer = false, is_signed = false;
};

bool scalar_type(std::string_view name, ScalarType& t) {
  static const std::pair<std::string_view, ScalarType> types[] = {
      {"char", {1, true, true}},     {"int8", {1, true, true}},     {"uchar", {1, true, false}},
      {"uint8", {1, true, false}},   {"short", {2, true, true}},    {"int16", {2, true, true}},
      {"ushort", {2, true, false}},  {"uint16", {2, true, false}},  {"int", {4, true, true}},
      {"int32", {4, true, true}},    {"uint", {4, true, false}},    {"uint32", {4, true, false}},
      {"float", {4, false, true}},   {"float32", {4, false, true}}, {"double", {8, false, true}},
      {"float64", {8, false, true}},
  };
  for (const auto& [n, ty] : types)
    if (n == name) {
      t = ty;
      return true;
    }
  return false;
}

struct Property {
  std::string name;
  bool list = false;
  ScalarType count, item; // count: lists only
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t body = 0;                // offset of the first byte after end_header's line
  size_t after_first_element = 0; // offset of the line after the first "element" line
  // Offsets of the last letter of the vertex properties "texture_s" and "texture_t" (0: absent).
  size_t texture_s = 0, texture_t = 0;
  // [begin, end) of each comment, obj_info and blank line (with its line end).
  std::vector<std::pair<size_t, size_t>> comments;
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  for (size_t i = 0; i < line.size();) {
    while (i < line.size() && std::strchr(" \t\r", line[i]))
      ++i;
    size_t j = i;
    while (j < line.size() && !std::strchr(" \t\r", line[j]))
      ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

Header parse_header(const std::string& d, const std::string& prefix) {
  Header h;
  size_t pos = 0;
  int line_no = 0;
  bool have_format = false;
  while (true) {
    size_t eol = d.find('\n', pos);
    if (eol == std::string::npos)
      fail(prefix, "not a PLY file or truncated header (no end_header)");
    std::string_view line(d.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    auto t = split(line);
    auto bad = [&](std::string_view what) {
      fail(prefix, fmt::format("header line {}: {}", line_no, what));
    };
    if (line_no == 1 && (t.size() != 1 || (t[0] != "ply" && t[0] != "PLY")))
      fail(prefix, "not a PLY file (it does not start with \"ply\")");
    // Assimp's header parser ends a line at a NUL or a CR (and skips the next line after one it
    // does not know): with a control byte in a line it would read another layout than the one
    // checked here (a NUL in a comment, "end_header\r\r\n" crashed it). Only a line's last CR
    // (CRLF) is allowed, and tabs.
    {
      std::string_view l = line;
      if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
      for (char c : l)
        if ((uint8_t(c) < 0x20 && c != '\t') || uint8_t(c) == 0x7f)
          bad(fmt::format("a control byte (0x{:02x})", uint8_t(c)));
    }
    if (line_no == 1) continue;
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") {
      h.comments.push_back({size_t(line.data() - d.data()), pos});
      continue;
    }
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() != 3) bad("expected \"format <type> <version>\"");
      if (t[1] == "ascii")
        h.format = Format::Ascii;
      else if (t[1] == "binary_little_endian")
        h.format = Format::BinaryLE;
      else if (t[1] == "binary_big_endian")
        h.format = Format::BinaryBE;
      else
        bad(fmt::format("unknown format '{}'", printable(t[1], 40)));
      have_format = true;
    } else if (t[0] == "element") {
      Element e;
      auto r = t.size() == 3 ? std::from_chars(t[2].data(), t[2].data() + t[2].size(), e.count)
                             : std::from_chars_result{nullptr, std::errc::invalid_argument};
      if (r.ec != std::errc() || r.ptr != t[2].data() + t[2].size())
        bad("expected \"element <name> <count>\"");
      e.name = t[1];
      if (h.elements.empty()) h.after_first_element = pos;
      h.elements.push_back(std::move(e));
    } else if (t[0] == "property") {
      if (h.elements.empty()) bad("a property before any element");
      Property p;
      bool ok;
      if (t.size() == 5 && t[1] == "list") {
        p.list = true;
        ok = scalar_type(t[2], p.count) && p.count.integer && scalar_type(t[3], p.item);
        p.name = t[4];
      } else {
        ok = t.size() == 3 && scalar_type(t[1], p.item);
        p.name = t.size() == 3 ? t[2] : "";
      }
      if (!ok) bad(fmt::format("bad property '{}'", printable(line, 60)));
      Element& e = h.elements.back();
      if (e.name == "vertex" && !p.list && (p.name == "texture_s" || p.name == "texture_t"))
        (p.name == "texture_s" ? h.texture_s : h.texture_t) = size_t(t[2].data() - d.data()) + 8;
      e.props.push_back(std::move(p));
    } else {
      bad(fmt::format("unknown keyword '{}'", printable(t[0], 40)));
    }
  }
  if (!have_format) fail(prefix, "the header has no format line");
  h.body = pos;
  return h;
}

std::string where(const Element& e, uint64_t i) {
  return fmt::format("{} {} of {}", printable(e.name, 40), i + 1, e.count);
}

bool face_indices(const Element& e, const Property& p) {
  return e.name == "face" && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

// A list's length limit: faces as for OBJ (Assimp triangulates in quadratic time); other lists
// are only skipped over.
uint64_t max_list(const Element& e, const Property& p) {
  return face_indices(e, p) ? uint64_t(kMaxPolygonVertices) : UINT64_MAX;
}

// The vertex count the header declares (0 without a vertex element; the smallest if there are
// several, whichever of them Assimp reads).
uint64_t vertex_count(const Header& h) {
  uint64_t n = UINT64_MAX;
  for (const Element& e : h.elements)
    if (e.name == "vertex") n = std::min(n, e.count);
  return n == UINT64_MAX ? 0 : n;
}

// Face indices are checked before Assimp sees them: its triangulation reads the vertices of a
// polygon by index, so one out of range crashes it, and it aborts on a face without vertices
// (an assertion in TriangulateProcess; the checks refuse such a face).
void check_index(double v, const Element& e, uint64_t i, uint64_t vertices,
                 const std::string& prefix) {
  if (!(v >= 0.0 && v < double(vertices)))
    fail(prefix, fmt::format("{}: the vertex index {} is out of range [0, {})", where(e, i),
                             fmt::format("{}", v), vertices));
}

// The value of a binary integer of type t at p.
int64_t read_int(const char* p, const ScalarType& t, bool big_endian) {
  uint64_t u = 0;
  for (int k = 0; k < t.size; ++k) {
    int b = big_endian ? k : t.size - 1 - k;
    u = (u << 8) | uint8_t(p[b]);
  }
  if (t.is_signed && t.size < 8 && (u >> (8 * t.size - 1)) & 1u) u |= ~uint64_t(0) << (8 * t.size);
  return int64_t(u);
}

// The value of a binary scalar of type t at p, as double.
double read_value(const char* p, const ScalarType& t, bool big_endian) {
  if (t.integer) return double(read_int(p, t, big_endian));
  ScalarType bits = t;
  bits.is_signed = false;
  const uint64_t u = uint64_t(read_int(p, bits, big_endian));
  if (t.size == 4) {
    float f;
    const uint32_t u32 = uint32_t(u);
    std::memcpy(&f, &u32, 4);
    return double(f);
  }
  double v;
  std::memcpy(&v, &u, 8);
  return v;
}

void check_binary(const std::string& d, const Header& h, const std::string& prefix) {
  const bool be = h.format == Format::BinaryBE;
  const uint64_t vertices = vertex_count(h);
  size_t pos = h.body;
  auto truncated = [&](const Element& e, uint64_t i) {
    fail(prefix, fmt::format("truncated: the file ends in {} ({} bytes)", where(e, i), d.size()));
  };
  for (const Element& e : h.elements) {
    bool fixed = std::none_of(e.props.begin(), e.props.end(), [](auto& p) { return p.list; });
    if (fixed) {
      uint64_t row = 0;
      for (const Property& p : e.props)
        row += uint64_t(p.item.size);
      if (row == 0) continue;
      uint64_t rows = (d.size() - pos) / row;
      if (rows < e.count) truncated(e, rows);
      pos += size_t(e.count * row);
      continue;
    }
    for (uint64_t i = 0; i < e.count; ++i)
      for (const Property& p : e.props) {
        uint64_t n = 1;
        if (p.list) {
          if (d.size() - pos < size_t(p.count.size)) truncated(e, i);
          int64_t c = read_int(d.data() + pos, p.count, be);
          pos += size_t(p.count.size);
          if (c < 0 || uint64_t(c) > max_list(e, p))
            fail(prefix, fmt::format("{}: list \"{}\" has {} entries", where(e, i),
                                     printable(p.name, 40), c));
          n = uint64_t(c);
          if (n == 0 && face_indices(e, p))
            fail(prefix, fmt::format("{}: a face without vertices", where(e, i)));
        }
        if (n > (d.size() - pos) / uint64_t(p.item.size)) truncated(e, i);
        if (face_indices(e, p))
          for (uint64_t j = 0; j < n; ++j)
            check_index(read_value(d.data() + pos + j * uint64_t(p.item.size), p.item, be), e, i,
                        vertices, prefix);
        pos += size_t(n * uint64_t(p.item.size));
      }
  }
}

bool numeric(std::string_view tok, bool integer, int64_t* value = nullptr) {
  if (tok.size() > 1 && tok[0] == '+') tok.remove_prefix(1); // Assimp accepts it; from_chars not
  const char* end = tok.data() + tok.size();
  if (integer) {
    int64_t v = 0;
    auto r = std::from_chars(tok.data(), end, v);
    if (value) *value = v;
    return r.ec == std::errc() && r.ptr == end;
  }
  double v = 0;
  auto r = std::from_chars(tok.data(), end, v);
  return r.ptr == end && (r.ec == std::errc() || r.ec == std::errc::result_out_of_range);
}

// One element instance per line (blank lines are skipped, as Assimp does); values past the
// element's properties are ignored, as Assimp does.
void check_ascii(const std::string& d, const Header& h, const std::string& prefix) {
  const uint64_t vertices = vertex_count(h);
  size_t pos = h.body;
  int line_no = int(std::count(d.begin(), d.begin() + ptrdiff_t(h.body), '\n'));
  for (const Element& e : h.elements)
    for (uint64_t i = 0; i < e.count; ++i) {
      std::vector<std::string_view> t;
      while (t.empty()) {
        if (pos >= d.size())
          fail(prefix,
               fmt::format("truncated: the file ends in {} (line {})", where(e, i), line_no + 1));
        size_t eol = std::min(d.find('\n', pos), d.size());
        t = split(std::string_view(d.data() + pos, eol - pos));
        pos = eol + 1;
        ++line_no;
      }
      size_t k = 0;
      auto bad = [&](std::string_view what) {
        fail(prefix, fmt::format("line {}: {}: {}", line_no, where(e, i), what));
      };
      for (const Property& p : e.props) {
        uint64_t n = 1;
        if (p.list) {
          int64_t c = 0;
          if (k >= t.size()) bad("too few values");
          if (!numeric(t[k++], true, &c) || c < 0 || uint64_t(c) > max_list(e, p))
            bad(fmt::format("list \"{}\" has the length '{}'", printable(p.name, 40),
                            printable(t[k - 1], 40)));
          n = uint64_t(c);
          if (n == 0 && face_indices(e, p)) bad("a face without vertices");
        }
        if (n > t.size() - k) bad("too few values");
        for (uint64_t j = 0; j < n; ++j, ++k) {
          if (!numeric(t[k], p.item.integer))
            bad(fmt::format("'{}' is not a{} number", printable(t[k], 40),
                            p.item.integer ? "n integer" : ""));
          if (face_indices(e, p)) {
            std::string_view tok = t[k];
            if (tok.size() > 1 && tok[0] == '+') tok.remove_prefix(1);
            double v = 0.0;
            auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
            if (r.ec != std::errc() || !(v >= 0.0 && v < double(vertices)))
              bad(fmt::format("the vertex index {} is out of range [0, {})", printable(t[k], 40),
                              vertices));
          }
        }
      }
    }
}

// Assimp reads uv named "u"/"v", "s"/"t" and "texture_u"/"texture_v" but not pbrt-v4's fourth
// spelling "texture_s"/"texture_t": those names are changed to "texture_u"/"texture_v" in the
// header (the same length, so the body stays where it is).
void rename_texture_st(std::string& d, const Header& h) {
  if (!h.texture_s || !h.texture_t) return;
  d[h.texture_s] = 'u';
  d[h.texture_t] = 'v';
}

// The file as Assimp 5.2 can read it, worked around two of its bugs:
// - It ends an element's properties at a comment, obj_info or blank line and then skips the
//   properties after it (so it read another layout than the one checked and crashed; found by
//   the fuzzer): those lines are removed from the header.
// - It skips whitespace after end_header's line even in a binary file, so a body whose first byte
//   is 0x09-0x0d or 0x20 (say, a little-endian float x whose low byte is '\n') is read one or more
//   bytes late: garbage, or an ai_assert abort in its triangulation. Such a file gets a one-byte
//   property "canopy_pad" ('!', not whitespace) before the others of its first element, which
//   must be "vertex" without lists (Assimp ignores unknown properties).
void rewrite_for_assimp(std::string& d, const Header& h, const std::string& prefix) {
  bool pad = false;
  size_t row = 0;
  const Element& first = h.elements.front();
  if (h.format != Format::Ascii && h.body < d.size()) {
    const char c = d[h.body];
    pad = c == ' ' || (c >= '\t' && c <= '\r');
  }
  if (pad) {
    bool ok = first.name == "vertex";
    for (const Property& p : first.props) {
      ok = ok && !p.list;
      row += size_t(p.item.size);
    }
    if (!ok || row == 0)
      fail(prefix, "not read: its binary data starts with a whitespace byte, which Assimp skips "
                   "(only a first element \"vertex\" without list properties is worked around)");
  }
  if (!pad && h.comments.empty()) return;
  std::string out;
  out.reserve(d.size() + (pad ? first.count + 32 : 0));
  size_t from = 0, next_comment = 0;
  // Copies the header up to offset `to`, leaving out the comment lines (whole lines: none
  // straddles a line boundary such as after_first_element).
  auto copy_header_until = [&](size_t to) {
    for (; next_comment < h.comments.size() && h.comments[next_comment].first < to;
         ++next_comment) {
      out.append(d, from, h.comments[next_comment].first - from);
      from = h.comments[next_comment].second;
    }
    out.append(d, from, to - from);
    from = to;
  };
  if (pad) {
    copy_header_until(h.after_first_element);
    out += "property uchar canopy_pad\n";
  }
  copy_header_until(h.body);
  if (pad) {
    size_t pos = h.body; // check_binary has seen every row
    for (uint64_t i = 0; i < first.count; ++i, pos += row) {
      out += '!';
      out.append(d, pos, row);
    }
    out.append(d, pos, std::string::npos);
  } else {
    out.append(d, h.body, std::string::npos);
  }
  d.swap(out);
}

std::string one_line(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  return s;
}

} // namespace

PlyMesh load_ply_mesh(const std::filesystem::path& file, const std::string& prefix) {
  std::string data = read_input_file(file, kMaxPlyFileBytes, prefix);
  if (file.extension() == ".gz") data = gunzip(data, kMaxPlyFileBytes, prefix);
  const Header h = parse_header(data, prefix);
  if (h.format == Format::Ascii)
    check_ascii(data, h, prefix);
  else
    check_binary(data, h, prefix);

  PlyMesh out;
  uint64_t vertices = 0, faces = 0;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") vertices = e.count;
    if (e.name == "face") faces = e.count;
  }
  // Assimp makes a point cloud of a file without faces; there is nothing to render in it.
  if (vertices == 0 || faces == 0) return out;
  rename_texture_st(data, h);
  rewrite_for_assimp(data, h, prefix);

  Assimp::Importer importer;
  // Triangulation only: no welding (aiProcess_JoinIdenticalVertices), no generated normals, no
  // validation pass that would drop or reorder data.
  const aiScene* scene =
      importer.ReadFileFromMemory(data.data(), data.size(), aiProcess_Triangulate, "ply");
  if (!scene) fail(prefix, fmt::format("not read: {}", one_line(importer.GetErrorString())));
  if (scene->mNumMeshes != 1)
    fail(prefix, fmt::format("not read: Assimp made {} meshes of it", scene->mNumMeshes));
  const aiMesh& m = *scene->mMeshes[0];
  if (m.mNumVertices != vertices)
    fail(prefix,
         fmt::format("not read: Assimp read {} of its {} vertices", m.mNumVertices, vertices));
  out.positions.resize(m.mNumVertices);
  for (unsigned v = 0; v < m.mNumVertices; ++v)
    out.positions[v] = make_float3(m.mVertices[v].x, m.mVertices[v].y, m.mVertices[v].z);
  if (m.HasNormals()) {
    out.normals.resize(m.mNumVertices);
    for (unsigned v = 0; v < m.mNumVertices; ++v)
      out.normals[v] = make_float3(m.mNormals[v].x, m.mNormals[v].y, m.mNormals[v].z);
  }
  if (m.HasTextureCoords(0) && m.mNumUVComponents[0] >= 2) {
    out.uv.resize(m.mNumVertices);
    for (unsigned v = 0; v < m.mNumVertices; ++v)
      out.uv[v] = make_float2(m.mTextureCoords[0][v].x, m.mTextureCoords[0][v].y);
  }
  out.indices.reserve(size_t(m.mNumFaces) * 3);
  for (unsigned f = 0; f < m.mNumFaces; ++f) {
    const aiFace& face = m.mFaces[f];
    if (face.mNumIndices < 3) {
      ++out.skipped_faces;
      continue;
    }
    if (face.mNumIndices > 3) fail(prefix, "not read: Assimp left a polygon untriangulated");
    for (unsigned k = 0; k < 3; ++k)
      if (face.mIndices[k] >= m.mNumVertices)
        fail(prefix, fmt::format("a face has the vertex index {}, out of range [0, {})",
                                 int32_t(face.mIndices[k]), m.mNumVertices));
    out.indices.insert(out.indices.end(), face.mIndices, face.mIndices + 3);
  }
  return out;
}

} // namespace canopy::detail
