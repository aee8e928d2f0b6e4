// pbrt-v4 reader: the tokens of a pbrt file and the lexer that makes them, with the source
// location every message names (file:line).
#pragma once

#include "scene/scene.h"

#include <string>
#include <string_view>
#include <utility>

namespace canopy::pbrt {

struct Loc {
  const std::string* file = nullptr;
  int line = 0;
};

// Throws the SceneError "<file>:<line>: msg".
[[noreturn]] void fail(const Loc& loc, std::string_view msg);

enum class Tok { String, Number, LBracket, RBracket, Ident };

struct Token {
  Tok kind;
  std::string text; // string content, identifier, or the number as written
  double num = 0.0;
  Loc loc;
};

inline bool is_bool_ident(const Token& t) {
  return t.kind == Tok::Ident && (t.text == "true" || t.text == "false");
}

// The format page, "Basic structure": '#' starts a comment to the end of the line; strings are
// double-quoted on one line; numbers, brackets and bare identifiers (directives, true/false)
// are separated by white space. Tokens are made one at a time as the reader asks for them, so a
// mesh of N numbers costs N doubles, not N tokens.
class Lexer {
public:
  Lexer(const std::string& text, const std::string* file) : text_(text), file_(file) {}
  // The next token, or nullptr at the end of the text.
  const Token* peek() {
    if (!has_) has_ = lex(tok_);
    return has_ ? &tok_ : nullptr;
  }
  // Consumes and returns the next token; the caller has checked peek().
  Token next() {
    peek();
    has_ = false;
    return std::move(tok_);
  }
  // True at the end of the text or at the next directive (an identifier other than true/false).
  bool at_directive() {
    const Token* t = peek();
    return !t || (t->kind == Tok::Ident && !is_bool_ident(*t));
  }
  Loc here() const { return {file_, line_}; }

private:
  bool lex(Token& out);

  const std::string& text_;
  const std::string* file_;
  size_t i_ = 0;
  int line_ = 1;
  Token tok_{Tok::Ident, {}, 0.0, {}};
  bool has_ = false;
};

// A token as messages quote it.
std::string describe(const Token& t);

} // namespace canopy::pbrt
