// The wavefront program from the program cache (ClRuntime::build_program, host/cl/program_cache.h)
// is the program built from source: it renders the same film bit for bit. A program's entry
// depends on its build options and on every kernel source and header, not on where the sources
// are; a corrupt entry is rebuilt and replaced without an error.
#include "cl/program_cache.h"
#include "cl/runtime.h"
#include "render/features.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

using namespace canopy;
namespace fs = std::filesystem;

namespace {

const char* kScene = R"({
  "camera": { "position": [0, 1.5, 2.8], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 70 },
  "film": { "width": 16, "height": 12 },
  "integrator": { "spp": 2, "max_depth": 3 },
  "materials": [ { "name": "white", "albedo": 0.7 } ],
  "shapes": [ { "type": "box", "material": "white", "min": [-3, 0, -3], "max": [3, 3, 3] } ],
  "lights": [
    { "type": "point", "position": [0, 2.5, 0], "intensity": [5, 5, 5] },
    { "type": "quad", "corner": [-1, 2.95, 1], "edge1": [2, 0, 0], "edge2": [0, 0, 0.5], "radiance": 3 }
  ]
})";

class ProgramCacheKernelTest : public ::testing::Test {
protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("canopy-test-kcache-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    setenv("CANOPY_CACHE_DIR", (dir_ / "cache").c_str(), 1);
  }
  void TearDown() override {
    unsetenv("CANOPY_KERNEL_DIR");
    fs::remove_all(dir_);
  }
  size_t entries() const {
    std::error_code ec;
    size_t n = 0;
    for (auto it = fs::directory_iterator(dir_ / "cache", ec); !ec && it != fs::end(it); ++it)
      n += it->path().extension() == ".bin";
    return n;
  }
  fs::path only_entry() const { return fs::directory_iterator(dir_ / "cache")->path(); }
  // The options of the default scene's tree program.
  std::string options(int sampler = light_sampler_from_name("tree")) const {
    return KernelFeatures::all(sampler).build_options();
  }

  ClRuntime rt_;
  fs::path dir_;
};

TEST_F(ProgramCacheKernelTest, CachedProgramRendersTheSameFilm) {
  Scene scene = load_scene_from_string(kScene, "cache.json", ".");
  RendererOptions opt;
  opt.light_sampler = "tree";
  RenderSettings rs;
  rs.spp = 2;
  Renderer fresh(rt_, scene, opt);
  ASSERT_FALSE(fresh.stats().program_from_cache);
  ASSERT_EQ(entries(), 1u);
  Film a = fresh.render(rs);
  Renderer cached(rt_, scene, opt);
  ASSERT_TRUE(cached.stats().program_from_cache);
  Film b = cached.render(rs);
  ASSERT_EQ(a.sum.size(), b.sum.size());
  EXPECT_EQ(std::memcmp(a.sum.data(), b.sum.data(), a.sum.size() * sizeof(double4)), 0);
  EXPECT_EQ(std::memcmp(a.sumsq.data(), b.sumsq.data(), a.sumsq.size() * sizeof(double4)), 0);
  EXPECT_EQ(std::memcmp(a.counts.data(), b.counts.data(), a.counts.size() * sizeof(double4)), 0);
}

TEST_F(ProgramCacheKernelTest, EntryDependsOnTheOptions) {
  bool cached = true;
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_TRUE(cached);
  rt_.build_program(wavefront_kernel_files(), options(light_sampler_from_name("power")), &cached);
  EXPECT_FALSE(cached);
  EXPECT_EQ(entries(), 2u);
}

TEST_F(ProgramCacheKernelTest, EntryDependsOnEveryHeader) {
  // A copy of the kernel sources, then one header changed (a comment: the same program text after
  // preprocessing, but the cache does not preprocess).
  const fs::path cl = dir_ / "cl";
  fs::create_directories(dir_);
  fs::copy(kernel_dir(), cl, fs::copy_options::recursive);
  setenv("CANOPY_KERNEL_DIR", cl.c_str(), 1);
  bool cached = true;
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_TRUE(cached);
  std::ofstream(cl / "rng.h", std::ios::app) << "// changed\n";
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
  EXPECT_EQ(entries(), 2u);
}

TEST_F(ProgramCacheKernelTest, EntryDoesNotDependOnWhereTheSourcesAre) {
  // Two checkouts of the same sources (a clean clone in CI, an installed copy): one entry.
  fs::create_directories(dir_);
  for (const char* copy : {"a", "b"}) {
    fs::create_directories(dir_ / copy / "cl");
    fs::copy(kernel_dir(), dir_ / copy / "cl", fs::copy_options::recursive);
  }
  bool cached = true;
  setenv("CANOPY_KERNEL_DIR", (dir_ / "a" / "cl").c_str(), 1);
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
  setenv("CANOPY_KERNEL_DIR", (dir_ / "b" / "cl").c_str(), 1);
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_TRUE(cached);
  EXPECT_EQ(entries(), 1u);
}

TEST_F(ProgramCacheKernelTest, CorruptEntryIsRebuiltSilently) {
  bool cached = true;
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  ASSERT_EQ(entries(), 1u);
  const fs::path entry = only_entry();
  const auto size = fs::file_size(entry);
  // The entry's key (after the magic and the format number: its length, then the key).
  std::string key;
  {
    std::ifstream in(entry, std::ios::binary);
    uint64_t n = 0;
    in.seekg(12);
    in.read(reinterpret_cast<char*>(&n), sizeof(n));
    key.resize(n);
    in.read(key.data(), std::streamsize(n));
  }
  // Truncated in the middle of the binary; cut to nothing; garbage of the same size; a well-formed
  // entry whose binary is garbage (the driver refuses it).
  for (int kind = 0; kind < 4; ++kind) {
    if (kind < 2) fs::resize_file(entry, kind == 0 ? size / 2 : 0);
    if (kind == 2)
      std::ofstream(entry, std::ios::binary | std::ios::trunc) << std::string(size, 'x');
    if (kind == 3) {
      ASSERT_TRUE(ProgramCache(dir_ / "cache").store(key, {'n', 'o', 't', 0, 1, 2}));
    }
    cl::Program p = rt_.build_program(wavefront_kernel_files(), options(), &cached);
    EXPECT_FALSE(cached) << "corruption " << kind;
    EXPECT_NO_THROW(cl::Kernel(p, "generate")) << "corruption " << kind;
    EXPECT_EQ(fs::file_size(entry), size) << "rewritten after corruption " << kind;
    rt_.build_program(wavefront_kernel_files(), options(), &cached);
    EXPECT_TRUE(cached) << "corruption " << kind;
  }
}

TEST_F(ProgramCacheKernelTest, NoCacheWhenTheDirectoryIsEmpty) {
  setenv("CANOPY_CACHE_DIR", "", 1);
  bool cached = true;
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
  rt_.build_program(wavefront_kernel_files(), options(), &cached);
  EXPECT_FALSE(cached);
}

} // namespace
