// A small path-tracking reader over a parsed JSON document: every accessor knows where in the
// document it is, so every validation error names the file and the JSON path, e.g. "scene.json:
// lights[3].radius: must be > 0".
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace canopy::detail {

// "<file>: <path>: <problem>" (path "(root)" for the document itself).
[[noreturn]] void throw_error(const std::string& file, const std::string& path,
                              std::string_view problem);

// The parsed JSON document: a flat array of 16-byte nodes, each container's children contiguous.
// A value's JSON path is built only when a message needs it (path(): a search for the parents,
// linear in the document, once per error). Strings without escapes point into the source text,
// which must outlive the document.
class Document {
public:
  enum class Type : uint8_t {
    null,
    boolean,
    integer,
    unsigned_integer,
    floating,
    string,
    array,
    object
  };
  static constexpr uint32_t kNone = 0xffffffffu;
  struct Node {
    Type type = Type::null;
    bool in_text = false; // string: bytes are in the source text (else in the arena)
    uint32_t n = 0;       // string: bytes; array: elements; object: members
    union {
      bool b;
      int64_t i;
      uint64_t u;
      double f;
      uint64_t str;   // string: offset in the text or the arena
      uint32_t first; // array: first element; object: first key (keys and values alternate)
    };
    Node() : u(0) {}
    uint32_t span() const { return type == Type::object ? 2 * n : type == Type::array ? n : 0; }
  };

  const Node& node(uint32_t i) const { return nodes[i]; }
  std::string_view str(const Node& n) const {
    return n.in_text ? text.substr(n.str, n.n) : std::string_view(arena).substr(n.str, n.n);
  }
  // "lights[3].position" ("" for the root); keys shortened for messages.
  std::string path(uint32_t i) const;
  // The array or object holding node i (kNone for the root).
  uint32_t parent(uint32_t i) const;

  std::string_view text;
  std::string arena; // decoded strings that had escapes
  std::vector<Node> nodes;
  uint32_t root = kNone;
};

// Parses JSON text (comments allowed) into `doc`, which refers to `text`. A syntax error becomes
// "<file>: line L, column C: <problem>", a duplicate key "<file>: <path>: duplicate key".
void parse_json(const std::string& text, const std::string& file, Document& doc);

// The fast parser alone: true and a complete `doc` if `text` is valid JSON without duplicate
// keys whose numbers it can convert exactly like nlohmann-json; false otherwise (parse_json then
// takes nlohmann-json's parser for the message). Exposed for tests.
bool fast_parse_json(std::string_view text, Document& doc);

class JsonObject;

class JsonValue {
public:
  JsonValue(const Document& doc, uint32_t index, const std::string& file)
      : doc_(&doc), i_(index), file_(&file) {}

  [[noreturn]] void fail(std::string_view problem) const;
  std::string path() const { return doc_->path(i_); }
  const std::string& file() const { return *file_; }
  const Document& doc() const { return *doc_; }
  uint32_t index() const { return i_; }
  const Document::Node& node() const { return doc_->node(i_); }

  bool is_object() const { return node().type == Document::Type::object; }
  bool is_array() const { return node().type == Document::Type::array; }
  bool is_string() const { return node().type == Document::Type::string; }
  bool is_number() const {
    auto t = node().type;
    return t == Document::Type::integer || t == Document::Type::unsigned_integer ||
           t == Document::Type::floating;
  }

  // Scalars. Every number must be finite (also after conversion to float).
  double as_double() const;
  float as_float() const;
  float as_float_positive() const;               // > 0
  float as_float_nonneg() const;                 // >= 0
  float as_float_in(float lo, float hi) const;   // [lo, hi]
  float as_float_open(float lo, float hi) const; // (lo, hi)
  int64_t as_int(int64_t lo, int64_t hi) const;  // integral value in [lo, hi]
  bool as_bool() const;
  std::string as_string() const;
  std::string as_enum(std::initializer_list<std::string_view> allowed) const;
  std::string as_enum(std::span<const std::string_view> allowed) const;

  // Vectors: an array of 3 finite numbers.
  float3 as_vec3() const;
  float3 as_vec3_nonzero() const;
  // The same checks, kept in double: positions, which the loader rounds to float only after
  // subtracting the scene origin (Scene::origin).
  double3 as_dvec3() const;
  // Colours: a number (grey) or an array of 3 numbers, every component >= 0.
  float3 as_color() const;
  // An emission: components >= 0; black means switched off (the loader skips such a light).
  float3 as_emission() const;
  // Reflectance: components in [0, 1].
  float3 as_albedo() const;
  // A colour with every component in [lo, hi].
  float3 as_color_in(float lo, float hi) const;

  size_t array_size() const;
  JsonValue at(size_t i) const; // requires an array
  std::vector<JsonValue> as_array() const;
  JsonObject as_object() const;

private:
  const Document* doc_;
  uint32_t i_;
  const std::string* file_;
};

// An object whose keys are checked: allow() rejects any key not in the list (and not read yet);
// get()/req() record the keys they read.
class JsonObject {
public:
  explicit JsonObject(const JsonValue& v);

  const JsonValue& self() const { return v_; }
  [[noreturn]] void fail(std::string_view problem) const { v_.fail(problem); }

  // Every key of the object must be in `keys` (or already read); the first other key is an error
  // "<path>.<key>: unknown key".
  void allow(std::initializer_list<std::string_view> keys) const;

  bool has(std::string_view key) const;
  JsonValue req(std::string_view key) const;                // required
  std::optional<JsonValue> get(std::string_view key) const; // optional

  float get_float(std::string_view key, float def) const;
  bool get_bool(std::string_view key, bool def) const;
  std::string child_path(std::string_view key) const;

private:
  // Index of the member named `key`, or npos.
  size_t find(std::string_view key) const;
  void mark_read(size_t member) const;
  bool was_read(size_t member) const;

  JsonValue v_;
  // Members read by get()/req(): a bit per member (the first 64 inline, no allocation per light).
  mutable uint64_t read_mask_ = 0;
  mutable std::vector<bool> read_more_;
};

} // namespace canopy::detail
