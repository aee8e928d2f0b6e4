#include "scene/json_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace canopy::detail {

void throw_error(const std::string& file, const std::string& path, std::string_view problem) {
  throw SceneError(fmt::format("{}: {}: {}", file, path.empty() ? "(root)" : path, problem));
}

namespace {

// Keys are echoed in JSON paths; a longer key is cut with an ellipsis.
constexpr size_t kMaxKeyChars = 64;

// Tracks the JSON path during parsing so a duplicate key (which nlohmann would silently resolve to
// the last value) is reported as "<file>: <path>.<key>: duplicate key".
class DuplicateKeyCheck {
public:
  explicit DuplicateKeyCheck(const std::string& file) : file_(file) {}

  bool operator()(int /*depth*/, json::parse_event_t ev, json& parsed) {
    using E = json::parse_event_t;
    switch (ev) {
    case E::object_start:
      frames_.push_back({false, 0, {}, {}});
      break;
    case E::array_start:
      frames_.push_back({true, 0, {}, {}});
      break;
    case E::key: {
      Frame& f = frames_.back();
      f.key = parsed.get<std::string>();
      if (!f.keys.insert(f.key).second) throw_error(file_, path(), "duplicate key");
      f.key = printable(f.key, kMaxKeyChars);
      break;
    }
    case E::object_end:
    case E::array_end:
      frames_.pop_back();
      if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
      break;
    case E::value:
      if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
      break;
    }
    return true;
  }

private:
  struct Frame {
    bool is_array;
    size_t index;
    std::string key;
    std::set<std::string> keys;
  };
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.is_array) {
        p += fmt::format("[{}]", f.index);
      } else {
        if (!p.empty()) p += '.';
        p += f.key;
      }
    }
    return p;
  }
  const std::string& file_;
  std::vector<Frame> frames_;
};

// 1-based line and column of byte offset `pos`.
std::pair<size_t, size_t> line_col(const std::string& text, size_t pos) {
  size_t line = 1, col = 1;
  for (size_t i = 0; i < pos && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

// First occurrence of a number token outside strings and comments.
size_t find_number_token(const std::string& text, const std::string& token) {
  auto is_num = [](char c) {
    return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E';
  };
  size_t n = text.size();
  for (size_t i = 0; i < n; ++i) {
    char c = text[i];
    if (c == '"') { // skip a string
      for (++i; i < n && text[i] != '"'; ++i)
        if (text[i] == '\\') ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i < n && text[i] != '\n')
        ++i;
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      size_t e = text.find("*/", i + 2);
      i = e == std::string::npos ? n : e + 1;
    } else if (text.compare(i, token.size(), token) == 0 && (i == 0 || !is_num(text[i - 1])) &&
               (i + token.size() >= n || !is_num(text[i + token.size()]))) {
      return i;
    }
  }
  return std::string::npos;
}

} // namespace

json parse_json(const std::string& text, const std::string& file) {
  try {
    // Comments (// and /* */) are allowed in scene files.
    return json::parse(text, DuplicateKeyCheck(file), /*allow_exceptions=*/true,
                       /*ignore_comments=*/true);
  } catch (const json::parse_error& e) {
    // e.byte is the 1-based offset of the character where parsing stopped.
    size_t end = std::min<size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
    auto [line, col] = line_col(text, end);
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line L, column C:
    // <problem>"; keep only the problem, on one line.
    std::string what = e.what();
    std::string problem = what;
    if (auto c = what.find("column "); c != std::string::npos) {
      if (auto colon = what.find(": ", c); colon != std::string::npos)
        problem = what.substr(colon + 2);
    } else if (auto colon = what.find("] "); colon != std::string::npos) {
      problem = what.substr(colon + 2);
    }
    std::replace(problem.begin(), problem.end(), '\n', ' ');
    throw SceneError(fmt::format("{}: line {}, column {}: {}", file, line, col, problem));
  } catch (const json::out_of_range& e) {
    // A number too large for a double (1e999): nlohmann reports it without a position, but names
    // the token; locate it in the text.
    std::string what = e.what();
    std::string token;
    if (auto a = what.find("parsing '"); a != std::string::npos) {
      auto b = what.rfind('\'');
      if (b != std::string::npos && b > a + 9) token = what.substr(a + 9, b - a - 9);
    }
    size_t pos = token.empty() ? std::string::npos : find_number_token(text, token);
    if (pos != std::string::npos) {
      auto [line, col] = line_col(text, pos);
      throw SceneError(fmt::format("{}: line {}, column {}: number {} is out of range (must be "
                                   "finite)",
                                   file, line, col, token));
    }
    throw SceneError(fmt::format("{}: number out of range (must be finite)", file));
  } catch (const json::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw SceneError(fmt::format("{}: {}", file, what));
  }
}

// ------------------------------------------------------------------------------------ JsonValue

void JsonValue::fail(std::string_view problem) const {
  throw_error(*file_, path_, problem);
}

double JsonValue::as_double() const {
  if (!j_->is_number()) fail("must be a number");
  double d = j_->get<double>();
  if (!std::isfinite(d)) fail("must be finite");
  return d;
}

float JsonValue::as_float() const {
  double d = as_double();
  if (std::fabs(d) > double(std::numeric_limits<float>::max())) fail("must be finite");
  return float(d);
}

float JsonValue::as_float_positive() const {
  float f = as_float();
  if (!(f > 0.0f)) fail("must be > 0");
  return f;
}

float JsonValue::as_float_nonneg() const {
  float f = as_float();
  if (!(f >= 0.0f)) fail("must be >= 0");
  return f;
}

float JsonValue::as_float_in(float lo, float hi) const {
  float f = as_float();
  if (!(f >= lo && f <= hi)) fail(fmt::format("must be in [{}, {}]", lo, hi));
  return f;
}

float JsonValue::as_float_open(float lo, float hi) const {
  float f = as_float();
  if (!(f > lo && f < hi)) fail(fmt::format("must be in ({}, {})", lo, hi));
  return f;
}

int64_t JsonValue::as_int(int64_t lo, int64_t hi) const {
  int64_t v = 0;
  if (j_->is_number_unsigned()) {
    uint64_t u = j_->get<uint64_t>();
    if (u > uint64_t(hi)) fail(fmt::format("must be in [{}, {}]", lo, hi));
    v = int64_t(u);
  } else if (j_->is_number_integer()) {
    v = j_->get<int64_t>();
  } else if (j_->is_number_float()) {
    // 1e6 is a float in JSON; accept it when it is an exact integer.
    double d = j_->get<double>();
    if (!std::isfinite(d)) fail("must be finite");
    if (d != std::floor(d) || std::fabs(d) > 9.0e15) fail("must be an integer");
    v = int64_t(d);
  } else {
    fail("must be an integer");
  }
  if (v < lo || v > hi) {
    if (hi == std::numeric_limits<int64_t>::max()) fail(fmt::format("must be >= {}", lo));
    fail(fmt::format("must be in [{}, {}]", lo, hi));
  }
  return v;
}

bool JsonValue::as_bool() const {
  if (!j_->is_boolean()) fail("must be true or false");
  return j_->get<bool>();
}

std::string JsonValue::as_string() const {
  if (!j_->is_string()) fail("must be a string");
  return j_->get<std::string>();
}

std::string JsonValue::as_enum(std::initializer_list<std::string_view> allowed) const {
  std::string s = as_string();
  for (auto a : allowed)
    if (s == a) return s;
  std::string list;
  for (auto a : allowed) {
    if (!list.empty()) list += ", ";
    list += a;
  }
  fail(fmt::format("unknown value \"{}\" (expected one of: {})", printable(s), list));
}

float3 JsonValue::as_vec3() const {
  if (!j_->is_array() || j_->size() != 3) fail("must be an array of 3 numbers");
  float c[3];
  for (size_t i = 0; i < 3; ++i)
    c[i] = at(i).as_float();
  return make_float3(c[0], c[1], c[2]);
}

float3 JsonValue::as_vec3_nonzero() const {
  float3 v = as_vec3();
  if (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f) fail("must not be the zero vector");
  return v;
}

float3 JsonValue::as_color() const {
  if (j_->is_number()) {
    float g = as_float();
    if (!(g >= 0.0f)) fail("must be >= 0");
    return make_float3(g, g, g);
  }
  if (!j_->is_array() || j_->size() != 3) fail("must be a number or an array of 3 numbers");
  float c[3];
  for (size_t i = 0; i < 3; ++i)
    c[i] = at(i).as_float_nonneg();
  return make_float3(c[0], c[1], c[2]);
}

float3 JsonValue::as_emission() const {
  // Zero is allowed: a light switched off, skipped by the loader.
  return as_color();
}

float3 JsonValue::as_albedo() const {
  if (j_->is_number()) {
    float g = as_float_in(0.0f, 1.0f);
    return make_float3(g, g, g);
  }
  if (!j_->is_array() || j_->size() != 3) fail("must be a number or an array of 3 numbers");
  float c[3];
  for (size_t i = 0; i < 3; ++i)
    c[i] = at(i).as_float_in(0.0f, 1.0f);
  return make_float3(c[0], c[1], c[2]);
}

size_t JsonValue::array_size() const {
  if (!j_->is_array()) fail("must be an array");
  return j_->size();
}

JsonValue JsonValue::at(size_t i) const {
  if (!j_->is_array()) fail("must be an array");
  return JsonValue((*j_)[i], fmt::format("{}[{}]", path_, i), *file_);
}

std::vector<JsonValue> JsonValue::as_array() const {
  size_t n = array_size();
  std::vector<JsonValue> out;
  out.reserve(n);
  for (size_t i = 0; i < n; ++i)
    out.push_back(at(i));
  return out;
}

JsonObject JsonValue::as_object() const {
  return JsonObject(*this);
}

// ----------------------------------------------------------------------------------- JsonObject

JsonObject::JsonObject(const JsonValue& v) : v_(v) {
  if (!v.raw().is_object()) v.fail("must be an object");
}

std::string JsonObject::child_path(std::string_view key) const {
  std::string k = printable(key, kMaxKeyChars);
  if (v_.path().empty()) return k;
  return fmt::format("{}.{}", v_.path(), k);
}

void JsonObject::allow(std::initializer_list<std::string_view> keys) const {
  for (auto it = v_.raw().begin(); it != v_.raw().end(); ++it) {
    const std::string& k = it.key();
    bool ok = std::find(keys.begin(), keys.end(), std::string_view(k)) != keys.end() ||
              std::find(read_.begin(), read_.end(), k) != read_.end();
    if (!ok) throw_error(v_.file(), child_path(k), "unknown key");
  }
}

bool JsonObject::has(std::string_view key) const {
  return v_.raw().contains(key);
}

JsonValue JsonObject::req(std::string_view key) const {
  auto v = get(key);
  if (!v) throw_error(v_.file(), child_path(key), "required key is missing");
  return *v;
}

std::optional<JsonValue> JsonObject::get(std::string_view key) const {
  auto it = v_.raw().find(key);
  if (it == v_.raw().end()) return std::nullopt;
  if (std::find(read_.begin(), read_.end(), key) == read_.end()) read_.emplace_back(key);
  return JsonValue(*it, child_path(key), v_.file());
}

float JsonObject::get_float(std::string_view key, float def) const {
  auto v = get(key);
  return v ? v->as_float() : def;
}

bool JsonObject::get_bool(std::string_view key, bool def) const {
  auto v = get(key);
  return v ? v->as_bool() : def;
}

} // namespace canopy::detail
