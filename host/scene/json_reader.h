// A small path-tracking reader over nlohmann::json: every accessor knows where in the document it
// is, so every validation error names the file and the JSON path, e.g.
// "scene.json: lights[3].radius: must be > 0".
#pragma once

#include "scene/scene.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace canopy::detail {

using json = nlohmann::json;

// "<file>: <path>: <problem>" (path "(root)" for the document itself).
[[noreturn]] void throw_error(const std::string& file, const std::string& path,
                              std::string_view problem);

// Parses JSON text; a syntax error becomes "<file>: line L, column C: <problem>".
json parse_json(const std::string& text, const std::string& file);

class JsonObject;

class JsonValue {
public:
  JsonValue(const json& j, std::string path, const std::string& file)
      : j_(&j), path_(std::move(path)), file_(&file) {}

  [[noreturn]] void fail(std::string_view problem) const;
  const std::string& path() const { return path_; }
  const std::string& file() const { return *file_; }
  const json& raw() const { return *j_; }

  bool is_object() const { return j_->is_object(); }
  bool is_array() const { return j_->is_array(); }
  bool is_string() const { return j_->is_string(); }
  bool is_number() const { return j_->is_number(); }

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

  // Vectors: an array of 3 finite numbers.
  float3 as_vec3() const;
  float3 as_vec3_nonzero() const;
  // Colours: a number (grey) or an array of 3 numbers, every component >= 0.
  float3 as_color() const;
  // An emission: components >= 0; black means switched off (the loader skips such a light).
  float3 as_emission() const;
  // Reflectance: components in [0, 1].
  float3 as_albedo() const;

  size_t array_size() const;
  JsonValue at(size_t i) const; // requires an array
  std::vector<JsonValue> as_array() const;
  JsonObject as_object() const;

private:
  const json* j_;
  std::string path_;
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
  JsonValue v_;
  mutable std::vector<std::string> read_;
};

} // namespace canopy::detail
