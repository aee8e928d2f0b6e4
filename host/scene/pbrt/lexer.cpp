#include "scene/pbrt/lexer.h"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace canopy::pbrt {

[[noreturn]] void fail(const Loc& loc, std::string_view msg) {
  throw SceneError(fmt::format("{}:{}: {}", *loc.file, loc.line, msg));
}

bool Lexer::lex(Token& out) {
  const std::string& text = text_;
  size_t& i = i_;
  const size_t n = text.size();
  auto delim = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '[' || c == ']' || c == '"' ||
           c == '#';
  };
  while (i < n) {
    char c = text[i];
    const Loc loc{file_, line_};
    if (c == '\n') {
      ++line_;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++i;
    } else if (c == '#') {
      while (i < n && text[i] != '\n')
        ++i;
    } else if (c == '[' || c == ']') {
      out = {c == '[' ? Tok::LBracket : Tok::RBracket, std::string(1, c), 0.0, loc};
      ++i;
      return true;
    } else if (c == '"') {
      out = {Tok::String, {}, 0.0, loc};
      ++i;
      bool closed = false;
      while (i < n) {
        char d = text[i++];
        if (d == '"') {
          closed = true;
          break;
        }
        if (d == '\n') break;
        if (d == '\\' && i < n && text[i] != '\n') {
          char e = text[i++];
          d = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == 'b' ? '\b' : e;
        }
        out.text.push_back(d);
      }
      if (!closed) fail(loc, "unterminated string");
      return true;
    } else if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') {
      size_t j = i;
      while (j < n && !delim(text[j]))
        ++j;
      out = {Tok::Number, text.substr(i, j - i), 0.0, loc};
      std::string_view sv(out.text);
      if (!sv.empty() && sv[0] == '+') sv.remove_prefix(1);
      double v = 0.0;
      auto r = std::from_chars(sv.data(), sv.data() + sv.size(), v);
      if (sv.empty() || r.ec != std::errc() || r.ptr != sv.data() + sv.size())
        fail(loc, fmt::format("bad number '{}'", printable(out.text)));
      if (!std::isfinite(v)) fail(loc, fmt::format("number '{}' is not finite", out.text));
      out.num = v;
      i = j;
      return true;
    } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_') {
      size_t j = i;
      while (j < n && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_'))
        ++j;
      out = {Tok::Ident, text.substr(i, j - i), 0.0, loc};
      i = j;
      return true;
    } else {
      fail(loc, fmt::format("unexpected character '{}'", printable(text.substr(i, 1))));
    }
  }
  return false;
}

std::string describe(const Token& t) {
  switch (t.kind) {
  case Tok::String:
    return fmt::format("\"{}\"", printable(t.text, 40));
  case Tok::Number:
    return t.text;
  case Tok::LBracket:
    return "[";
  case Tok::RBracket:
    return "]";
  default:
    return printable(t.text, 40);
  }
}

} // namespace canopy::pbrt
