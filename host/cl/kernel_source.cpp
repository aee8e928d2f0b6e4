#include "cl/kernel_source.h"

#include "cl/runtime.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <vector>

namespace canopy {

namespace {

namespace fs = std::filesystem;

std::optional<std::string> read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The directive on this line and its first argument ("ifndef", "X" for `#ifndef X`), or "".
std::pair<std::string_view, std::string_view> directive(std::string_view line) {
  auto word = [&](std::string_view chars) {
    const size_t b = line.find_first_not_of(" \t");
    if (b == std::string_view::npos) return std::string_view();
    line.remove_prefix(b);
    const size_t e = std::min(line.find_first_not_of(chars), line.size());
    const std::string_view w = line.substr(0, e);
    line.remove_prefix(e);
    return w;
  };
  if (word("#") != "#") return {};
  const std::string_view name = word("abcdefghijklmnopqrstuvwxyz");
  return {name, word("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_")};
}

// The file named by `#include "file"` on this line, or nothing (another line, or an angle include).
std::optional<std::string> quoted_include(std::string_view line) {
  if (directive(line).first != "include") return std::nullopt;
  const size_t open = line.find_first_not_of(" \t", line.find("include") + 7);
  if (open == std::string_view::npos || line[open] != '"') return std::nullopt;
  const size_t close = line.find('"', open + 1);
  if (close == std::string_view::npos) return std::nullopt;
  return std::string(line.substr(open + 1, close - open - 1));
}

// Whether the file's first two directives are `#ifndef X` and `#define X` (its include guard).
bool has_include_guard(std::string_view text) {
  std::string_view first;
  while (!text.empty()) {
    const size_t end = std::min(text.find('\n'), text.size());
    const auto [name, arg] = directive(text.substr(0, end));
    text.remove_prefix(std::min(end + 1, text.size()));
    if (name.empty()) continue;
    if (first.empty()) {
      if (name != "ifndef" || arg.empty()) return false;
      first = arg;
    } else {
      return name == "define" && arg == first;
    }
  }
  return false;
}

// One translation unit: the kernel files of a program are one source, so a guarded header
// expanded once where the compiler surely reads it (outside every #if but its own guard, from a
// file read the same way) is read as empty at every later include, and left out there. Everywhere
// else an include is expanded again: its earlier text may sit in a branch the compiler skips.
struct Expander {
  const fs::path& root;
  std::vector<std::string> stack;          // the files being expanded, outermost first
  std::map<std::string, std::string> text; // each file read once
  std::set<std::string> done;              // guarded headers the compiler has surely read

  const std::string* read(const std::string& name) {
    auto it = text.find(name);
    if (it == text.end()) {
      std::optional<std::string> body = read_file(root / name);
      if (!body) return nullptr;
      it = text.emplace(name, std::move(*body)).first;
    }
    return &it->second;
  }

  // The include's name relative to root: next to the including file first, then in root.
  std::optional<std::string> resolve(const std::string& including, const std::string& inc) const {
    const std::string near = (fs::path(including).parent_path() / inc).lexically_normal().string();
    if (fs::is_regular_file(root / near)) return near;
    const std::string top = fs::path(inc).lexically_normal().string();
    if (fs::is_regular_file(root / top)) return top;
    return std::nullopt;
  }

  // `conditional`: the compiler may skip this file's text (it is included inside an #if).
  void expand(const std::string& body, const std::string& name, bool conditional,
              std::string& out) {
    stack.push_back(name);
    const bool guarded = has_include_guard(body);
    int depth = guarded ? -1 : 0; // #if nesting, the guard's own not counted
    size_t begin = 0;
    for (int line_no = 1; begin < body.size(); ++line_no) {
      size_t end = body.find('\n', begin);
      if (end == std::string::npos) end = body.size();
      const std::string_view line(body.data() + begin, end - begin);
      begin = end + 1;
      const std::string_view d = directive(line).first;
      depth += d.substr(0, 2) == "if" ? 1 : d == "endif" ? -1 : 0;
      const std::optional<std::string> inc = quoted_include(line);
      if (!inc) {
        out.append(line);
        out += '\n';
        continue;
      }
      const std::optional<std::string> file = resolve(name, *inc);
      if (!file)
        throw ClError(fmt::format("{}:{}: cannot find #include \"{}\"", (root / name).string(),
                                  line_no, *inc));
      const bool sure = !conditional && depth == 0;
      bool skip = done.count(*file) > 0;
      for (const std::string& s : stack)
        skip = skip || s == *file;
      if (!skip) {
        const std::string* inc_body = read(*file);
        if (!inc_body)
          throw ClError(fmt::format("{}: cannot read kernel header", (root / *file).string()));
        out += fmt::format("#line 1 \"{}\"\n", *file);
        expand(*inc_body, *file, !sure, out);
        if (sure && has_include_guard(*inc_body)) done.insert(*file);
      }
      out += fmt::format("#line {} \"{}\"\n", line_no + 1, name);
    }
    stack.pop_back();
  }
};

} // namespace

std::string expand_kernel_includes(const std::string& text, const std::string& name,
                                   const fs::path& root) {
  Expander e{root, {}, {}, {}};
  std::string out;
  e.expand(text, name, false, out);
  return out;
}

std::string read_kernel_sources(const fs::path& root, const std::vector<std::string>& names) {
  Expander e{root, {}, {}, {}};
  std::string out;
  for (const std::string& name : names) {
    const std::string* text = e.read(name);
    if (!text) throw ClError(fmt::format("{}: cannot open kernel source", (root / name).string()));
    out += fmt::format("#line 1 \"{}\"\n", name);
    e.expand(*text, name, false, out);
  }
  return out;
}

} // namespace canopy
