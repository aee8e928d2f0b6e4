// Kernel sources with their includes expanded (host/cl/kernel_source.h): every quoted include is
// replaced by its file's text, found where the compiler would find it; `#line` keeps each line's
// file and number; the text holds no absolute path; a missing include is a one-line error.
#include "cl/kernel_source.h"
#include "cl/runtime.h"
#include "render/renderer.h"
#include "support/test_temp_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

using namespace canopy;
namespace fs = std::filesystem;

namespace {

class KernelSourceTest : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = test::test_temp_dir("source");
    fs::remove_all(dir_); // a fresh tree: what a failed run left would change the expansion
    fs::create_directories(dir_ / "sub");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }

  fs::path dir_;
};

TEST_F(KernelSourceTest, IncludesAreExpandedWithLineDirectives) {
  write("top.h", "int top;\n");
  write("sub/a.h", "int a0;\n#include \"../top.h\"\nint a2;\n");
  write("main.cl", "int m0;\n  #  include \"sub/a.h\" // a comment\nint m2;\n#include <x.h>\n");
  EXPECT_EQ(read_kernel_sources(dir_, {"main.cl"}), "#line 1 \"main.cl\"\n"
                                                    "int m0;\n"
                                                    "#line 1 \"sub/a.h\"\n"
                                                    "int a0;\n"
                                                    "#line 1 \"top.h\"\n"
                                                    "int top;\n"
                                                    "#line 3 \"sub/a.h\"\n"
                                                    "int a2;\n"
                                                    "#line 3 \"main.cl\"\n"
                                                    "int m2;\n"
                                                    "#include <x.h>\n");
}

TEST_F(KernelSourceTest, IncludeFoundNextToTheIncluderBeforeTheRoot) {
  write("b.h", "int root_b;\n");
  write("sub/b.h", "int sub_b;\n");
  write("sub/a.h", "#include \"b.h\"\n");
  write("c.h", "#include \"b.h\"\n");
  const std::string a = expand_kernel_includes("#include \"sub/a.h\"\n", "s", dir_);
  EXPECT_NE(a.find("int sub_b;"), std::string::npos) << a;
  EXPECT_EQ(a.find("int root_b;"), std::string::npos) << a;
  // sub/c.h does not exist: "c.h" from sub/a.h's neighbour falls back to the root.
  write("sub/a.h", "#include \"c.h\"\n");
  const std::string c = expand_kernel_includes("#include \"sub/a.h\"\n", "s", dir_);
  EXPECT_NE(c.find("int root_b;"), std::string::npos) << c;
}

TEST_F(KernelSourceTest, TextIsTheSameInEveryCheckout) {
  write("a.h", "int a;\n");
  write("sub/b.h", "#include \"../a.h\"\n");
  const fs::path other = dir_.string() + "-copy";
  fs::remove_all(other);
  fs::copy(dir_, other, fs::copy_options::recursive);
  const std::string here = expand_kernel_includes("#include \"sub/b.h\"\n", "s", dir_);
  const std::string there = expand_kernel_includes("#include \"sub/b.h\"\n", "s", other);
  fs::remove_all(other);
  EXPECT_EQ(here, there);
  EXPECT_EQ(here.find(dir_.string()), std::string::npos) << here;
}

TEST_F(KernelSourceTest, CycleEndsAtTheFileBeingExpanded) {
  write("a.h", "int a;\n#include \"b.h\"\n");
  write("b.h", "int b;\n#include \"a.h\"\n");
  const std::string s = expand_kernel_includes("#include \"a.h\"\n", "s", dir_);
  EXPECT_EQ(s, "#line 1 \"a.h\"\nint a;\n#line 1 \"b.h\"\nint b;\n#line 3 \"b.h\"\n"
               "#line 3 \"a.h\"\n#line 2 \"s\"\n");
}

TEST_F(KernelSourceTest, MissingIncludeNamesTheFileLineAndInclude) {
  write("a.h", "int a;\n\n#include \"nowhere.h\"\n");
  try {
    expand_kernel_includes("#include \"a.h\"\n", "s", dir_);
    FAIL() << "no error";
  } catch (const ClError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir_ / "a.h").string() + ":3:"), std::string::npos) << what;
    EXPECT_NE(what.find("\"nowhere.h\""), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(read_kernel_sources(dir_, {"missing.cl"}), ClError);
}

TEST_F(KernelSourceTest, GuardedHeaderReadOnceWhereTheCompilerSurelyReadsIt) {
  write("g.h", "// guarded\n#ifndef G_H\n#define G_H\nint g;\n#endif\n");
  write("u.h", "int u;\n"); // no guard: its text counts at every include
  write("c.h", "#ifndef C_H\n#define C_H\n#if FEATURE\n#include \"g.h\"\n#endif\n#endif\n");
  auto count = [](const std::string& s, const std::string& what) {
    size_t n = 0;
    for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1))
      ++n;
    return n;
  };
  // Unconditional includes in two files of one program: once.
  write("a.cl", "#include \"g.h\"\n#include \"u.h\"\n");
  write("b.cl", "#include \"g.h\"\n#include \"u.h\"\n#include \"g.h\"\n");
  std::string s = read_kernel_sources(dir_, {"a.cl", "b.cl"});
  EXPECT_EQ(count(s, "int g;"), 1u) << s;
  EXPECT_EQ(count(s, "int u;"), 2u) << s;
  // First inside an #if (the compiler may skip it), then unconditionally: both expanded.
  write("a.cl", "#if FEATURE\n#include \"g.h\"\n#endif\n#include \"g.h\"\n#include \"g.h\"\n");
  s = read_kernel_sources(dir_, {"a.cl"});
  EXPECT_EQ(count(s, "int g;"), 2u) << s;
  // Inside an #if of an included header: conditional too.
  write("a.cl", "#include \"c.h\"\n#include \"g.h\"\n");
  s = read_kernel_sources(dir_, {"a.cl"});
  EXPECT_EQ(count(s, "int g;"), 2u) << s;
  // Unconditional from a header that is itself included inside an #if: conditional.
  write("d.h", "#ifndef D_H\n#define D_H\n#include \"g.h\"\n#endif\n");
  write("a.cl", "#ifdef X\n#include \"d.h\"\n#endif\n#include \"g.h\"\n");
  s = read_kernel_sources(dir_, {"a.cl"});
  EXPECT_EQ(count(s, "int g;"), 2u) << s;
}

TEST_F(KernelSourceTest, TheWavefrontSourcesExpandToTextWithoutIncludesOrPaths) {
  const fs::path root = kernel_dir();
  ASSERT_FALSE(wavefront_kernel_files().empty());
  const std::string s = read_kernel_sources(root, wavefront_kernel_files());
  EXPECT_EQ(s.find("#include \""), std::string::npos);
  EXPECT_EQ(s.find(root.string()), std::string::npos);
  EXPECT_NE(s.find("#line 1 \"compat.h\""), std::string::npos);
  for (const std::string& file : wavefront_kernel_files())
    EXPECT_NE(s.find("#line 1 \"" + file + "\""), std::string::npos) << file;
}

} // namespace
