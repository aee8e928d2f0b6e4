// Partial images and their merge (image/partial_image.h), without rendering: the EXR round trip
// (data window inside the film's display window, canopy:* attributes), the merge's arithmetic
// (sample-count weights, coverage), and every refusal with one line naming the file.
#include "image/partial_image.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

using namespace canopy;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / "canopy_test_image_partial";
  fs::create_directories(dir);
  return dir / name;
}

// A partial image of a 6x4 film: window [x0, x1) x [y0, y1), samples [a, b), every channel of
// every pixel `value`.
PartialImage part(int x0, int y0, int x1, int y1, int a, int b, float value, uint32_t seed = 1) {
  PartialImage p;
  PartialInfo& i = p.info;
  i.scene = "scene.json";
  i.scene_hash = "00000000000000aa";
  i.version = canopy_version();
  i.seed = seed;
  i.film_width = 6;
  i.film_height = 4;
  i.x0 = x0, i.y0 = y0, i.x1 = x1, i.y1 = y1;
  i.sample_begin = a;
  i.sample_end = b;
  p.pixels.width = x1 - x0;
  p.pixels.height = y1 - y0;
  p.pixels.rgb.assign(size_t(3 * p.pixels.width * p.pixels.height), value);
  return p;
}

float pixel(const MergeResult& r, int x, int y) {
  return r.image.rgb[3 * size_t(y * r.image.width + x)];
}

// The one-line message of the MergeError that `f` throws (empty if none).
template <class F> std::string merge_error(F f) {
  try {
    f();
  } catch (const MergeError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(PartialImage, ExrRoundTripKeepsTheWindowAndTheAttributes) {
  PartialImage p = part(2, 1, 5, 3, 16, 48, 0.0f, 77);
  for (size_t k = 0; k < p.pixels.rgb.size(); ++k)
    p.pixels.rgb[k] = 0.25f * float(k) + 1e-3f;
  fs::path f = scratch("roundtrip.exr");
  write_partial_exr(f, p.pixels, p.info, {{"canopy:spp", "32"}});
  PartialImage q = read_partial_exr(f);
  EXPECT_EQ(q.info.scene, p.info.scene);
  EXPECT_EQ(q.info.scene_hash, p.info.scene_hash);
  EXPECT_EQ(q.info.version, p.info.version);
  EXPECT_EQ(q.info.seed, 77u);
  EXPECT_EQ(q.info.film_width, 6);
  EXPECT_EQ(q.info.film_height, 4);
  EXPECT_EQ(q.info.x0, 2);
  EXPECT_EQ(q.info.y0, 1);
  EXPECT_EQ(q.info.x1, 5);
  EXPECT_EQ(q.info.y1, 3);
  EXPECT_EQ(q.info.sample_begin, 16);
  EXPECT_EQ(q.info.sample_end, 48);
  EXPECT_EQ(q.pixels.rgb, p.pixels.rgb);
}

TEST(PartialImage, MergeWeightsBySampleCountAndReportsCoverage) {
  // Left half: samples [0, 1) valued 1 and [1, 4) valued 3 -> (1 + 9) / 4 = 2.5. Right half:
  // only [0, 1), valued 8: fewer samples, reported short.
  std::vector<PartialImage> parts = {part(0, 0, 3, 4, 0, 1, 1.0f), part(0, 0, 3, 4, 1, 4, 3.0f),
                                     part(3, 0, 6, 4, 0, 1, 8.0f)};
  MergeResult r = merge_partials(parts, {"a", "b", "c"});
  EXPECT_EQ(r.image.width, 6);
  EXPECT_FLOAT_EQ(pixel(r, 0, 0), 2.5f);
  EXPECT_FLOAT_EQ(pixel(r, 2, 3), 2.5f);
  EXPECT_FLOAT_EQ(pixel(r, 3, 0), 8.0f);
  EXPECT_EQ(r.min_samples, 1u);
  EXPECT_EQ(r.max_samples, 4u);
  EXPECT_EQ(r.short_pixels, 12u);
  EXPECT_FALSE(r.uniform);
  // Completing the right half makes the merge one range of the whole film.
  parts.push_back(part(3, 0, 6, 4, 1, 4, 0.0f));
  r = merge_partials(parts, {"a", "b", "c", "d"});
  EXPECT_TRUE(r.uniform);
  EXPECT_EQ(r.info.sample_begin, 0);
  EXPECT_EQ(r.info.sample_end, 4);
  EXPECT_FLOAT_EQ(pixel(r, 5, 3), 2.0f);
  EXPECT_EQ(r.short_pixels, 0u);
  // Pixels no input covers are black and short.
  r = merge_partials({part(0, 0, 2, 2, 0, 4, 1.0f)}, {"a"});
  EXPECT_EQ(r.min_samples, 0u);
  EXPECT_EQ(r.short_pixels, 20u);
  EXPECT_FLOAT_EQ(pixel(r, 4, 3), 0.0f);
  // Different seeds are independent samples: overlapping ranges merge (not one range, though).
  r = merge_partials({part(0, 0, 6, 4, 0, 4, 1.0f, 1), part(0, 0, 6, 4, 0, 4, 3.0f, 2)},
                     {"a", "b"});
  EXPECT_FLOAT_EQ(pixel(r, 1, 1), 2.0f);
  EXPECT_FALSE(r.uniform);
}

TEST(PartialImage, MergeRefusesInconsistentInputsWithOneLine) {
  PartialImage a = part(0, 0, 6, 4, 0, 4, 1.0f);
  PartialImage other_scene = part(0, 0, 6, 4, 4, 8, 1.0f);
  other_scene.info.scene_hash = "00000000000000bb";
  PartialImage other_film = part(0, 0, 6, 4, 4, 8, 1.0f);
  other_film.info.film_width = 7;
  PartialImage overlap = part(4, 3, 6, 4, 3, 6, 1.0f); // samples 3:4 of pixels (4..5, 3)
  struct Case {
    std::vector<PartialImage> parts;
    std::string expect;
  } cases[] = {
      {{a, other_scene},
       "b.exr: rendered from scene scene.json (hash 00000000000000bb), a.exr "
       "from scene.json (hash 00000000000000aa)"},
      {{a, other_film}, "b.exr: film 7x4, a.exr has 6x4"},
      {{a, overlap},
       "a.exr and b.exr both hold samples [3, 4) of seed 1 for pixels [4, 6) x [3, 4)"},
      {{}, "merge: no input images"},
  };
  for (const Case& c : cases) {
    std::string msg = merge_error([&] { merge_partials(c.parts, {"a.exr", "b.exr"}); });
    EXPECT_EQ(msg, c.expect);
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
}

TEST(PartialImage, ReadRefusesMissingTruncatedAndForeignFiles) {
  fs::path missing = scratch("missing.exr");
  fs::remove(missing);
  EXPECT_EQ(merge_error([&] { read_partial_exr(missing); }), missing.string() + ": no such file");

  // A valid partial image cut short.
  PartialImage p = part(0, 0, 6, 4, 0, 4, 0.5f);
  for (size_t k = 0; k < p.pixels.rgb.size(); ++k)
    p.pixels.rgb[k] = float(k); // incompressible enough that the pixels are most of the file
  fs::path whole = scratch("whole.exr"), cut = scratch("cut.exr");
  write_partial_exr(whole, p.pixels, p.info);
  std::ifstream in(whole, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size() * 2 / 3));
  std::string msg = merge_error([&] { read_partial_exr(cut); });
  EXPECT_EQ(msg.rfind(cut.string() + ": ", 0), 0u) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;

  // An EXR without Canopy's attributes.
  fs::path foreign = scratch("foreign.exr");
  write_exr(foreign, p.pixels);
  msg = merge_error([&] { read_partial_exr(foreign); });
  EXPECT_EQ(msg.rfind(foreign.string() + ": not a Canopy render (no canopy:samples", 0), 0u) << msg;

  // Not an image at all.
  fs::path text = scratch("text.exr");
  std::ofstream(text) << "hello\n";
  msg = merge_error([&] { read_partial_exr(text); });
  EXPECT_EQ(msg.rfind(text.string() + ": cannot read", 0), 0u) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(PartialImage, SceneHashFollowsTheBytes) {
  fs::path f = scratch("hash.json");
  std::ofstream(f) << "{}";
  std::string h1 = scene_file_hash(f);
  EXPECT_EQ(h1.size(), 16u);
  EXPECT_EQ(scene_file_hash(f), h1);
  std::ofstream(f) << "{ }";
  EXPECT_NE(scene_file_hash(f), h1);
}
