#include "scene/json_reader.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace canopy::detail {

void throw_error(const std::string& file, const std::string& path, std::string_view problem) {
  throw SceneError(fmt::format("{}: {}: {}", file, path.empty() ? "(root)" : path, problem));
}

using json = nlohmann::json;

namespace {

// Keys are echoed in JSON paths; a longer key is cut with an ellipsis.
constexpr size_t kMaxKeyChars = 64;

// nlohmann-json's parser, run only on text the fast parser (below) rejects, for its messages:
// builds nlohmann's DOM from its SAX events (what json::parse does) and rejects a duplicate key,
// which nlohmann would silently resolve to the last value, as "<file>: <path>.<key>: duplicate
// key". The check is the insertion into the object's own map, O(log keys); the path is built only
// for the message. (A parse callback did this check before, but nlohmann's callback parser scans
// the parent container at every object end: quadratic in the length of an array of objects, 10
// minutes for 10^6 lights.)
class DomBuilder {
public:
  DomBuilder(json& root, const std::string& file) : root_(root), file_(file) {}

  bool null() { return value(nullptr); }
  bool boolean(bool v) { return value(v); }
  bool number_integer(json::number_integer_t v) { return value(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value(v); }
  bool number_float(json::number_float_t v, const json::string_t& /*text*/) { return value(v); }
  bool string(json::string_t& v) { return value(std::move(v)); }
  bool binary(json::binary_t& v) { return value(std::move(v)); }

  bool start_object(std::size_t /*len: unknown for JSON text*/) {
    stack_.push_back({place(json::value_t::object), nullptr});
    return true;
  }
  bool key(json::string_t& k) {
    Frame& f = stack_.back();
    auto& obj = *f.node->get_ptr<json::object_t*>();
    auto [it, inserted] = obj.emplace(std::move(k), nullptr);
    if (!inserted) throw_error(file_, path(it->first), "duplicate key");
    f.key = &it->first;
    next_ = &it->second;
    return true;
  }
  bool end_object() {
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t /*len*/) {
    stack_.push_back({place(json::value_t::array), nullptr});
    return true;
  }
  bool end_array() {
    stack_.pop_back();
    return true;
  }
  // Rethrows nlohmann's own exception (parse_error, out_of_range), as json::parse would.
  template <class Exception>
  bool parse_error(std::size_t /*byte*/, const std::string& /*token*/, const Exception& ex) {
    throw ex;
  }

private:
  struct Frame {
    json* node;
    const std::string* key; // objects: the key being read
  };

  template <class V> bool value(V&& v) {
    place(std::forward<V>(v));
    return true;
  }
  template <class V> json* place(V&& v) {
    if (stack_.empty()) {
      root_ = json(std::forward<V>(v));
      return &root_;
    }
    json* parent = stack_.back().node;
    if (parent->is_array()) {
      auto& arr = *parent->get_ptr<json::array_t*>();
      arr.emplace_back(std::forward<V>(v));
      return &arr.back();
    }
    *next_ = json(std::forward<V>(v));
    return next_;
  }
  // "a.b[3].<dup>": parent keys shortened as in every other path, the duplicate key in full.
  std::string path(const std::string& dup) const {
    std::string p;
    for (size_t i = 0; i < stack_.size(); ++i) {
      const Frame& f = stack_[i];
      if (f.node->is_array()) {
        p += fmt::format("[{}]", f.node->size() - 1);
      } else {
        if (!p.empty()) p += '.';
        p += i + 1 == stack_.size() ? dup : printable(*f.key, kMaxKeyChars);
      }
    }
    return p;
  }

  json& root_;
  const std::string& file_;
  std::vector<Frame> stack_;
  json* next_ = nullptr; // where the value of the last key goes
};

// ------------------------------------------------------------------------------- fast parser
//
// One pass over the text, no recursion (nesting depth is unbounded, as in nlohmann-json), no
// allocation per value: scalars and finished containers are appended to a flat node array. The
// children of an open container wait on a stack; when it closes they move, contiguous, to the
// node array. The grammar is nlohmann-json's with comments (RFC 8259 plus // and /* */ where
// whitespace may be, a UTF-8 byte order mark at the start), numbers convert as nlohmann-json
// converts them (integers to int64/uint64 when they fit, else double; doubles correctly rounded,
// as strtod), and anything it does not accept (a syntax error, a duplicate key, a number out of
// range) makes it return false: parse_json then runs nlohmann-json's parser, whose messages
// are the reference.
class FastParser {
public:
  using Node = Document::Node;
  using Type = Document::Type;

  FastParser(std::string_view text, Document& doc)
      : b_(text.data()), p_(text.data()), e_(text.data() + text.size()), doc_(doc) {}

  bool run() {
    if (e_ - p_ >= 3 && uint8_t(p_[0]) == 0xef && uint8_t(p_[1]) == 0xbb && uint8_t(p_[2]) == 0xbf)
      p_ += 3;
    reserve();
    for (;;) {
      // A value.
      if (!ws() || p_ == e_) return false;
      char c = *p_;
      if (c == '{' || c == '[') {
        ++p_;
        open_.push_back({uint32_t(tmp_.size()), c == '{'});
        if (!ws()) return false;
        if (p_ < e_ && *p_ == (c == '{' ? '}' : ']')) {
          ++p_;
          if (!close()) return false;
        } else {
          if (c == '{' && !key()) return false;
          continue;
        }
      } else if (!scalar()) {
        return false;
      }
      // After a value: ',' (then a value, or a key and a value), or the end of containers.
      for (;;) {
        if (!ws()) return false;
        if (open_.empty()) return finish();
        if (p_ == e_) return false;
        bool obj = open_.back().object;
        if (*p_ == ',') {
          ++p_;
          if (obj && !key()) return false;
          break;
        }
        if (*p_ != (obj ? '}' : ']')) return false;
        ++p_;
        if (!close()) return false;
      }
    }
  }

private:
  struct Open {
    uint32_t start; // first child in tmp_
    bool object;
  };

  // Node count bound from the structural characters, so the node array is allocated once.
  void reserve() {
    size_t n = 1;
    for (const char* q = p_; q < e_; ++q)
      n += (*q == ',') | (*q == ':') | (*q == '[') | (*q == '{');
    doc_.nodes.reserve(std::min(n, size_t(e_ - p_) / 2 + 1));
  }

  // Skips whitespace and comments; false on a malformed comment.
  bool ws() {
    for (;;) {
      while (p_ < e_ && (*p_ == ' ' || *p_ == '\n' || *p_ == '\r' || *p_ == '\t'))
        ++p_;
      if (p_ == e_ || *p_ != '/') return true;
      if (e_ - p_ < 2) return false;
      if (p_[1] == '/') {
        p_ += 2;
        while (p_ < e_ && *p_ != '\n' && *p_ != '\r')
          ++p_;
      } else if (p_[1] == '*') {
        const char* q = p_ + 2;
        for (;; ++q) {
          if (e_ - q < 2) return false;
          if (q[0] == '*' && q[1] == '/') break;
        }
        p_ = q + 2;
      } else {
        return false;
      }
    }
  }

  bool key() {
    if (!ws() || p_ == e_ || *p_ != '"' || !string()) return false;
    if (!ws() || p_ == e_ || *p_ != ':') return false;
    ++p_;
    return true;
  }

  bool scalar() {
    Node n;
    char c = *p_;
    if (c == '"') return string();
    if (c == '-' || (c >= '0' && c <= '9')) return number();
    auto lit = [&](std::string_view w) {
      if (size_t(e_ - p_) < w.size() || std::string_view(p_, w.size()) != w) return false;
      p_ += w.size();
      return true;
    };
    if (c == 't' || c == 'f') {
      if (!lit(c == 't' ? "true" : "false")) return false;
      n.type = Type::boolean;
      n.b = c == 't';
    } else if (!lit("null")) {
      return false;
    }
    tmp_.push_back(n);
    return true;
  }

  // A number token (RFC 8259 grammar), converted like nlohmann-json's lexer: an integer to
  // uint64 (no sign) or int64 (minus) when it fits, otherwise, and for any fraction or exponent,
  // the correctly rounded double.
  bool number() {
    const char* s = p_;
    const char* q = p_;
    bool neg = *q == '-';
    if (neg) ++q;
    auto digits = [&] {
      const char* d = q;
      while (q < e_ && *q >= '0' && *q <= '9')
        ++q;
      return q > d;
    };
    if (q == e_) return false;
    if (*q == '0')
      ++q;
    else if (!digits())
      return false;
    bool integral = true;
    if (q < e_ && *q == '.') {
      ++q;
      if (!digits()) return false;
      integral = false;
    }
    if (q < e_ && (*q == 'e' || *q == 'E')) {
      ++q;
      if (q < e_ && (*q == '+' || *q == '-')) ++q;
      if (!digits()) return false;
      integral = false;
    }
    p_ = q;
    Node n;
    if (integral) {
      if (neg) {
        int64_t v = 0;
        auto r = std::from_chars(s, q, v);
        if (r.ec == std::errc() && r.ptr == q) {
          n.type = Type::integer;
          n.i = v;
          tmp_.push_back(n);
          return true;
        }
      } else {
        uint64_t v = 0;
        auto r = std::from_chars(s, q, v);
        if (r.ec == std::errc() && r.ptr == q) {
          n.type = Type::unsigned_integer;
          n.u = v;
          tmp_.push_back(n);
          return true;
        }
      }
    }
    double d = 0.0;
    auto r = std::from_chars(s, q, d);
    if (r.ptr != q) return false;
    if (r.ec == std::errc::result_out_of_range) {
      // Underflow (1e-400) or overflow: strtod's value, as nlohmann-json takes it.
      std::string tok(s, q);
      d = std::strtod(tok.c_str(), nullptr);
    } else if (r.ec != std::errc()) {
      return false;
    }
    if (!std::isfinite(d)) return false; // nlohmann-json: "number overflow"
    n.type = Type::floating;
    n.f = d;
    tmp_.push_back(n);
    return true;
  }

  // Length of the well-formed UTF-8 sequence at q (RFC 3629, the ranges nlohmann-json accepts),
  // 0 if ill-formed.
  int utf8_length(const char* q) const {
    auto at = [&](int k) { return q + k < e_ ? uint8_t(q[k]) : 0u; };
    auto in = [](unsigned v, unsigned lo, unsigned hi) { return v >= lo && v <= hi; };
    unsigned c = at(0);
    if (in(c, 0xc2, 0xdf)) return in(at(1), 0x80, 0xbf) ? 2 : 0;
    if (c == 0xe0) return in(at(1), 0xa0, 0xbf) && in(at(2), 0x80, 0xbf) ? 3 : 0;
    if (in(c, 0xe1, 0xec) || in(c, 0xee, 0xef))
      return in(at(1), 0x80, 0xbf) && in(at(2), 0x80, 0xbf) ? 3 : 0;
    if (c == 0xed) return in(at(1), 0x80, 0x9f) && in(at(2), 0x80, 0xbf) ? 3 : 0;
    if (c == 0xf0)
      return in(at(1), 0x90, 0xbf) && in(at(2), 0x80, 0xbf) && in(at(3), 0x80, 0xbf) ? 4 : 0;
    if (in(c, 0xf1, 0xf3))
      return in(at(1), 0x80, 0xbf) && in(at(2), 0x80, 0xbf) && in(at(3), 0x80, 0xbf) ? 4 : 0;
    if (c == 0xf4)
      return in(at(1), 0x80, 0x8f) && in(at(2), 0x80, 0xbf) && in(at(3), 0x80, 0xbf) ? 4 : 0;
    return 0;
  }

  // A string at p_ (the opening quote). Without escapes it stays in the text; with escapes it is
  // decoded into the arena.
  bool string() {
    const char* s = ++p_;
    while (p_ < e_) {
      uint8_t c = uint8_t(*p_);
      if (c == '"') {
        Node n;
        n.type = Type::string;
        n.in_text = true;
        n.str = uint64_t(s - b_);
        n.n = uint32_t(p_ - s);
        ++p_;
        tmp_.push_back(n);
        return true;
      }
      if (c == '\\') return escaped_string(s);
      if (c < 0x20) return false;
      if (c < 0x80) {
        ++p_;
      } else {
        int len = utf8_length(p_);
        if (len == 0) return false;
        p_ += len;
      }
    }
    return false;
  }

  bool hex4(uint32_t& v) {
    if (e_ - p_ < 4) return false;
    v = 0;
    for (int k = 0; k < 4; ++k) {
      char c = *p_++;
      uint32_t d = c >= '0' && c <= '9'   ? uint32_t(c - '0')
                   : c >= 'a' && c <= 'f' ? uint32_t(c - 'a' + 10)
                   : c >= 'A' && c <= 'F' ? uint32_t(c - 'A' + 10)
                                          : 16u;
      if (d == 16u) return false;
      v = v * 16 + d;
    }
    return true;
  }

  bool escaped_string(const char* s) {
    std::string& a = doc_.arena;
    size_t off = a.size();
    a.append(s, size_t(p_ - s));
    while (p_ < e_) {
      uint8_t c = uint8_t(*p_);
      if (c == '"') {
        Node n;
        n.type = Type::string;
        n.str = off;
        n.n = uint32_t(a.size() - off);
        ++p_;
        tmp_.push_back(n);
        return true;
      }
      if (c < 0x20) return false;
      if (c >= 0x80) {
        int len = utf8_length(p_);
        if (len == 0) return false;
        a.append(p_, size_t(len));
        p_ += len;
        continue;
      }
      if (c != '\\') {
        a += char(c);
        ++p_;
        continue;
      }
      if (++p_ == e_) return false;
      char x = *p_++;
      switch (x) {
      case '"':
        a += '"';
        break;
      case '\\':
        a += '\\';
        break;
      case '/':
        a += '/';
        break;
      case 'b':
        a += '\b';
        break;
      case 'f':
        a += '\f';
        break;
      case 'n':
        a += '\n';
        break;
      case 'r':
        a += '\r';
        break;
      case 't':
        a += '\t';
        break;
      case 'u': {
        uint32_t cp = 0;
        if (!hex4(cp)) return false;
        if (cp >= 0xdc00 && cp <= 0xdfff) return false; // a lone low surrogate
        if (cp >= 0xd800 && cp <= 0xdbff) {             // a high surrogate needs its low half
          uint32_t lo = 0;
          if (e_ - p_ < 2 || p_[0] != '\\' || p_[1] != 'u') return false;
          p_ += 2;
          if (!hex4(lo) || lo < 0xdc00 || lo > 0xdfff) return false;
          cp = 0x10000 + ((cp - 0xd800) << 10) + (lo - 0xdc00);
        }
        if (cp < 0x80) {
          a += char(cp);
        } else if (cp < 0x800) {
          a += char(0xc0 | (cp >> 6));
          a += char(0x80 | (cp & 0x3f));
        } else if (cp < 0x10000) {
          a += char(0xe0 | (cp >> 12));
          a += char(0x80 | ((cp >> 6) & 0x3f));
          a += char(0x80 | (cp & 0x3f));
        } else {
          a += char(0xf0 | (cp >> 18));
          a += char(0x80 | ((cp >> 12) & 0x3f));
          a += char(0x80 | ((cp >> 6) & 0x3f));
          a += char(0x80 | (cp & 0x3f));
        }
        break;
      }
      default:
        return false;
      }
    }
    return false;
  }

  // Closes the innermost container: its children move to the node array.
  bool close() {
    Open o = open_.back();
    open_.pop_back();
    size_t count = tmp_.size() - o.start;
    if (o.object && has_duplicate_key(o.start, count / 2)) return false;
    if (doc_.nodes.size() + count >= size_t(Document::kNone)) return false;
    Node n;
    n.type = o.object ? Type::object : Type::array;
    n.n = uint32_t(o.object ? count / 2 : count);
    n.first = uint32_t(doc_.nodes.size());
    doc_.nodes.insert(doc_.nodes.end(), tmp_.begin() + o.start, tmp_.end());
    tmp_.resize(o.start);
    tmp_.push_back(n);
    return true;
  }

  std::string_view key_at(size_t i) const {
    const Node& k = tmp_[i];
    return k.in_text ? std::string_view(b_ + k.str, k.n)
                     : std::string_view(doc_.arena).substr(k.str, k.n);
  }

  bool has_duplicate_key(size_t start, size_t members) {
    if (members <= 8) {
      for (size_t a = 0; a < members; ++a)
        for (size_t b = a + 1; b < members; ++b)
          if (key_at(start + 2 * a) == key_at(start + 2 * b)) return true;
      return false;
    }
    std::vector<std::string_view> keys(members);
    for (size_t a = 0; a < members; ++a)
      keys[a] = key_at(start + 2 * a);
    std::sort(keys.begin(), keys.end());
    return std::adjacent_find(keys.begin(), keys.end()) != keys.end();
  }

  bool finish() {
    if (p_ != e_ || tmp_.size() != 1) return false;
    if (doc_.nodes.size() + 1 >= size_t(Document::kNone)) return false;
    doc_.root = uint32_t(doc_.nodes.size());
    doc_.nodes.push_back(tmp_[0]);
    return true;
  }

  const char* b_;
  const char* p_;
  const char* e_;
  Document& doc_;
  std::vector<Node> tmp_;
  std::vector<Open> open_;
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

bool fast_parse_json(std::string_view text, Document& doc) {
  doc = Document{};
  doc.text = text;
  return FastParser(text, doc).run();
}

uint32_t Document::parent(uint32_t i) const {
  for (uint32_t c = 0; c < nodes.size(); ++c) {
    const Node& n = nodes[c];
    uint32_t span = n.span();
    if (span != 0 && i >= n.first && i - n.first < span) return c;
  }
  return kNone;
}

std::string Document::path(uint32_t i) const {
  std::vector<std::pair<uint32_t, uint32_t>> chain; // (node, its parent), innermost first
  for (uint32_t c = i; c != root;) {
    uint32_t p = parent(c);
    if (p == kNone) break; // not reached: every node but the root has a parent
    chain.emplace_back(c, p);
    c = p;
  }
  std::string p;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const Node& parent = nodes[it->second];
    if (parent.type == Type::array) {
      p += fmt::format("[{}]", it->first - parent.first);
    } else {
      if (!p.empty()) p += '.';
      p += printable(str(nodes[it->first - 1]), kMaxKeyChars);
    }
  }
  return p;
}

void parse_json(const std::string& text, const std::string& file, Document& doc) {
  if (fast_parse_json(text, doc)) return;
  doc = Document{};
  try {
    // nlohmann-json's parser, for its messages. Comments (// and /* */) are allowed.
    json j;
    DomBuilder builder(j, file);
    json::sax_parse(text, &builder, json::input_format_t::json, /*strict=*/true,
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
  // Both parsers implement the same grammar (tests/test_json_reader.cpp compares them).
  throw SceneError(fmt::format("{}: internal error: the JSON reader rejected text that "
                               "nlohmann-json accepts",
                               file));
}

// ------------------------------------------------------------------------------------ JsonValue

void JsonValue::fail(std::string_view problem) const {
  throw_error(*file_, path(), problem);
}

double JsonValue::as_double() const {
  if (!is_number()) fail("must be a number");
  const Document::Node& n = node();
  double d = n.type == Document::Type::floating  ? n.f
             : n.type == Document::Type::integer ? double(n.i)
                                                 : double(n.u);
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
  const Document::Node& n = node();
  if (n.type == Document::Type::unsigned_integer) {
    uint64_t u = n.u;
    if (u > uint64_t(hi)) fail(fmt::format("must be in [{}, {}]", lo, hi));
    v = int64_t(u);
  } else if (n.type == Document::Type::integer) {
    v = n.i;
  } else if (n.type == Document::Type::floating) {
    // 1e6 is a float in JSON; accept it when it is an exact integer.
    double d = n.f;
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
  if (node().type != Document::Type::boolean) fail("must be true or false");
  return node().b;
}

std::string JsonValue::as_string() const {
  if (!is_string()) fail("must be a string");
  return std::string(doc_->str(node()));
}

std::string JsonValue::as_enum(std::initializer_list<std::string_view> allowed) const {
  return as_enum(std::span<const std::string_view>(allowed.begin(), allowed.size()));
}

std::string JsonValue::as_enum(std::span<const std::string_view> allowed) const {
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
  if (!is_array() || node().n != 3) fail("must be an array of 3 numbers");
  float c[3];
  for (size_t i = 0; i < 3; ++i)
    c[i] = at(i).as_float();
  return make_float3(c[0], c[1], c[2]);
}

double3 JsonValue::as_dvec3() const {
  if (!is_array() || node().n != 3) fail("must be an array of 3 numbers");
  double c[3];
  for (size_t i = 0; i < 3; ++i) {
    // The range of as_float: the same inputs are accepted whether kept in double or not.
    JsonValue e = at(i);
    c[i] = e.as_double();
    if (std::fabs(c[i]) > double(std::numeric_limits<float>::max())) e.fail("must be finite");
  }
  return {c[0], c[1], c[2]};
}

float3 JsonValue::as_vec3_nonzero() const {
  float3 v = as_vec3();
  if (v.x == 0.0f && v.y == 0.0f && v.z == 0.0f) fail("must not be the zero vector");
  return v;
}

float3 JsonValue::as_color() const {
  if (is_number()) {
    float g = as_float();
    if (!(g >= 0.0f)) fail("must be >= 0");
    return make_float3(g, g, g);
  }
  if (!is_array() || node().n != 3) fail("must be a number or an array of 3 numbers");
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
  return as_color_in(0.0f, 1.0f);
}

float3 JsonValue::as_color_in(float lo, float hi) const {
  if (is_number()) {
    float g = as_float_in(lo, hi);
    return make_float3(g, g, g);
  }
  if (!is_array() || node().n != 3) fail("must be a number or an array of 3 numbers");
  float c[3];
  for (size_t i = 0; i < 3; ++i)
    c[i] = at(i).as_float_in(lo, hi);
  return make_float3(c[0], c[1], c[2]);
}

size_t JsonValue::array_size() const {
  if (!is_array()) fail("must be an array");
  return node().n;
}

JsonValue JsonValue::at(size_t i) const {
  if (!is_array()) fail("must be an array");
  return JsonValue(*doc_, node().first + uint32_t(i), *file_);
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
  if (!v.is_object()) v.fail("must be an object");
}

std::string JsonObject::child_path(std::string_view key) const {
  std::string k = printable(key, kMaxKeyChars);
  std::string p = v_.path();
  if (p.empty()) return k;
  return fmt::format("{}.{}", p, k);
}

size_t JsonObject::find(std::string_view key) const {
  const Document& d = v_.doc();
  const Document::Node& o = v_.node();
  for (uint32_t m = 0; m < o.n; ++m)
    if (d.str(d.node(o.first + 2 * m)) == key) return m;
  return std::string_view::npos;
}

void JsonObject::mark_read(size_t m) const {
  if (m < 64) {
    read_mask_ |= uint64_t(1) << m;
    return;
  }
  if (read_more_.size() <= m - 64) read_more_.resize(m - 64 + 1);
  read_more_[m - 64] = true;
}

bool JsonObject::was_read(size_t m) const {
  if (m < 64) return (read_mask_ >> m) & 1u;
  return m - 64 < read_more_.size() && read_more_[m - 64];
}

void JsonObject::allow(std::initializer_list<std::string_view> keys) const {
  // The first offending key in byte order (the order the messages have always used).
  const Document& d = v_.doc();
  const Document::Node& o = v_.node();
  std::optional<std::string_view> bad;
  for (uint32_t m = 0; m < o.n; ++m) {
    std::string_view k = d.str(d.node(o.first + 2 * m));
    bool ok = std::find(keys.begin(), keys.end(), k) != keys.end() || was_read(m);
    if (!ok && (!bad || k < *bad)) bad = k;
  }
  if (bad) throw_error(v_.file(), child_path(*bad), "unknown key");
}

bool JsonObject::has(std::string_view key) const {
  return find(key) != std::string_view::npos;
}

JsonValue JsonObject::req(std::string_view key) const {
  auto v = get(key);
  if (!v) throw_error(v_.file(), child_path(key), "required key is missing");
  return *v;
}

std::optional<JsonValue> JsonObject::get(std::string_view key) const {
  size_t m = find(key);
  if (m == std::string_view::npos) return std::nullopt;
  mark_read(m);
  return JsonValue(v_.doc(), v_.node().first + 2 * uint32_t(m) + 1, v_.file());
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
