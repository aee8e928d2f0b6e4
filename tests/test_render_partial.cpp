// Partial renders (issue 23): the sample range [A, B) and the window (crop) of a render change
// which samples are taken, never their values, so
// - renders of a partition of [0, N) into ranges, merged by sample count, equal one render of N spp
//   up to float rounding (relative difference <= 1e-5 per pixel);
// - a cropped render equals the full render's pixels in the window;
// - tiles x ranges merge into the full render, and the merge reports one uniform sample range.
// On scenes that take every stage: glossy-cornell (brdf-mis: splitting, BRDF-oriented rounds) and
// spiral-fog (a medium: segment light samples), with each path sampler (independent, sobol: a
// Sobol sample's numbers depend on its global sample index alone, cl/sampler.h).
#include "image/partial_image.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

using namespace canopy;

namespace {

constexpr int kW = 32, kH = 24, kSpp = 8;

class PartialRender : public ::testing::TestWithParam<std::tuple<const char*, const char*>> {
protected:
  void SetUp() override {
    scene_ = load_scene(std::string(CANOPY_SCENES_DIR) + "/" + std::get<0>(GetParam()) + ".json");
    scene_.film.width = kW;
    scene_.film.height = kH;
    scene_.integrator.max_depth = std::min(scene_.integrator.max_depth, 3);
    RendererOptions opt;
    opt.light_sampler = "brdf-mis";
    opt.path_sampler = std::get<1>(GetParam());
    renderer_ = std::make_unique<Renderer>(rt_, scene_, opt);
  }

  // The render of samples [a, b) of window `w` as a partial image.
  PartialImage render(int a, int b, PixelWindow w = {}) {
    RenderSettings rs;
    rs.seed = 5;
    rs.first_sample = a;
    rs.spp = b - a;
    rs.window = w;
    rs.wave_size = 997; // waves that cut across pixels and passes
    Film f = renderer_->render(rs);
    EXPECT_EQ(renderer_->stats().nonfinite_samples, 0u);
    PartialImage p;
    p.pixels = f.mean();
    p.info.scene_hash = "0123456789abcdef";
    p.info.seed = rs.seed;
    p.info.film_width = f.film_width;
    p.info.film_height = f.film_height;
    p.info.x0 = f.x0;
    p.info.y0 = f.y0;
    p.info.x1 = f.x0 + f.width;
    p.info.y1 = f.y0 + f.height;
    p.info.sample_begin = a;
    p.info.sample_end = b;
    return p;
  }

  // Every pixel of `part` (a window of the film) within `rel` of the full image's.
  static void expect_same_pixels(const PartialImage& part, const RgbImage& full, double rel,
                                 const char* what) {
    double worst = 0.0, total = 0.0;
    for (int y = part.info.y0; y < part.info.y1; ++y)
      for (int x = part.info.x0; x < part.info.x1; ++x)
        for (int c = 0; c < 3; ++c) {
          double a =
              part.pixels
                  .rgb[3 * size_t((y - part.info.y0) * part.pixels.width + (x - part.info.x0)) +
                       size_t(c)];
          double b = full.rgb[3 * size_t(y * full.width + x) + size_t(c)];
          double d = std::fabs(a - b) / std::max({std::fabs(a), std::fabs(b), 1e-30});
          worst = std::max(worst, d);
          total += b;
          EXPECT_LE(d, rel) << what << ": pixel (" << x << ", " << y << ") channel " << c << ": "
                            << a << " vs " << b;
        }
    EXPECT_GT(total, 0.0) << what << ": a black image proves nothing";
    std::printf("%s: worst relative difference %.3g\n", what, worst);
  }

  ClRuntime rt_;
  Scene scene_;
  std::unique_ptr<Renderer> renderer_;
};

std::vector<std::string> names_of(size_t n) {
  std::vector<std::string> names;
  for (size_t i = 0; i < n; ++i)
    names.push_back("part" + std::to_string(i));
  return names;
}

} // namespace

TEST_P(PartialRender, MergedSampleRangesEqualOneRender) {
  PartialImage full = render(0, kSpp);
  std::vector<PartialImage> parts = {render(0, 2), render(2, 3), render(3, 7), render(7, kSpp)};
  MergeResult m = merge_partials(parts, names_of(parts.size()));
  EXPECT_TRUE(m.uniform);
  EXPECT_EQ(m.info.sample_begin, 0);
  EXPECT_EQ(m.info.sample_end, kSpp);
  EXPECT_EQ(m.min_samples, uint32_t(kSpp));
  EXPECT_EQ(m.short_pixels, 0u);
  PartialImage merged;
  merged.info = m.info;
  merged.pixels = m.image;
  expect_same_pixels(merged, full.pixels, 1e-5, "4 ranges merged vs 1 render");
  // A single range is not the whole: a merge of half the ranges differs (the test can fail).
  MergeResult half = merge_partials({parts[0], parts[2]}, names_of(2));
  double diff = 0.0;
  for (size_t i = 0; i < full.pixels.rgb.size(); ++i)
    diff = std::max(diff, double(std::fabs(half.image.rgb[i] - full.pixels.rgb[i])));
  EXPECT_GT(diff, 1e-3);
  EXPECT_FALSE(half.uniform); // samples 0:2 and 3:7 are not one range
}

TEST_P(PartialRender, CropsEqualTheFullRendersPixels) {
  PartialImage full = render(0, kSpp);
  PixelWindow w{5, 3, 21, 17};
  PartialImage crop = render(0, kSpp, w);
  EXPECT_EQ(crop.pixels.width, 16);
  EXPECT_EQ(crop.pixels.height, 14);
  expect_same_pixels(crop, full.pixels, 1e-6, "crop vs full");
}

TEST_P(PartialRender, TilesAndRangesMergeIntoTheFullRender) {
  PartialImage full = render(0, kSpp);
  std::vector<PartialImage> parts;
  for (PixelWindow w : {PixelWindow{0, 0, 20, 10}, PixelWindow{20, 0, kW, 10},
                        PixelWindow{0, 10, 7, kH}, PixelWindow{7, 10, kW, kH}})
    for (auto [a, b] : {std::pair{0, 5}, std::pair{5, kSpp}})
      parts.push_back(render(a, b, w));
  MergeResult m = merge_partials(parts, names_of(parts.size()));
  EXPECT_TRUE(m.uniform);
  EXPECT_EQ(m.max_samples, uint32_t(kSpp));
  PartialImage merged;
  merged.info = m.info;
  merged.pixels = m.image;
  expect_same_pixels(merged, full.pixels, 1e-5, "4 tiles x 2 ranges merged vs 1 render");
  // Without the last tile's second range, its pixels are reported short.
  parts.pop_back();
  MergeResult missing = merge_partials(parts, names_of(parts.size()));
  EXPECT_FALSE(missing.uniform);
  EXPECT_EQ(missing.short_pixels, uint64_t((kW - 7) * (kH - 10)));
  EXPECT_EQ(missing.min_samples, 5u);
}

// A render of bands of the film's rows (in a window, over a sample range) equals the full render
// on the rows it covers, and has no samples on the others.
TEST_P(PartialRender, BandsOfRowsEqualTheFullRendersRows) {
  RenderSettings rs;
  rs.seed = 5;
  rs.first_sample = 2;
  rs.spp = 5;
  rs.window = PixelWindow{3, 1, 29, 23};
  rs.wave_size = 997;
  const Film full = renderer_->render(rs);
  rs.bands = RowBands{3, 4, 1, 2}; // rows 3-8 of every 12 of the window's 22
  renderer_->reset_render_stats();
  const Film part = renderer_->render(rs);
  ASSERT_EQ(part.width, full.width);
  ASSERT_EQ(part.height, full.height);
  EXPECT_EQ(renderer_->stats().samples, uint64_t(rs.spp) * 26 * 12); // rows 3-8, 15-20
  int covered = 0;
  for (int y = 0; y < part.height; ++y) {
    const bool in = (y / 3) % 4 == 1 || (y / 3) % 4 == 2;
    covered += in;
    for (int x = 0; x < part.width; ++x) {
      const size_t p = size_t(y * part.width + x);
      if (!in) {
        ASSERT_EQ(part.sum[p].w, 0.0) << x << ", " << y;
        continue;
      }
      ASSERT_EQ(part.sum[p].w, double(rs.spp));
      for (double d : {part.sum[p].x - full.sum[p].x, part.sum[p].y - full.sum[p].y,
                       part.sum[p].z - full.sum[p].z})
        ASSERT_LE(std::fabs(d), 1e-5 * std::fabs(full.sum[p].x + full.sum[p].y + full.sum[p].z))
            << x << ", " << y;
    }
  }
  EXPECT_EQ(covered, 12);
}

INSTANTIATE_TEST_SUITE_P(Scenes, PartialRender,
                         ::testing::Combine(::testing::Values("glossy-cornell", "spiral-fog"),
                                            ::testing::Values("independent", "sobol")),
                         [](const auto& p) {
                           std::string name =
                               std::string(std::get<0>(p.param)) + "_" + std::get<1>(p.param);
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });
