// Image textures (cl/texture.h). The lookup against hand-computed bilinear values and pbrt-v4's
// conventions (v = 0 at the image's bottom, texel centres at (i + 0.5) / n, wrap modes, uv
// mapping); images read with their encodings; and rendered planes against closed forms. A texture
// made of 2 x 2-texel blocks of one colour each filters to exactly that colour over the central
// texel-wide square of each block, so every pixel whose footprint lies there has a closed form: the
// block's rho / pi E cos(theta) under a distant light, or f cos I / d^2 of the block's albedo and
// roughness under a point light. Which block lands where checks the orientation.
#include "bsdf/bsdf.h"
#include "image/image_io.h"
#include "render/camera.h"
#include "render/features.h"
#include "render/renderer.h"
#include "render/texture_data.h"
#include "scene/scene.h"
#include "support/lit_plane.h"
#include "support/test_lights.h"
#include "texture.h"

#include "support/test_temp_dir.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

using namespace canopy;

namespace {

constexpr float kPi = 3.14159265358979323846f;

std::filesystem::path temp_dir() {
  return test::test_temp_dir("tex");
}

// A texture over host texels (row 0 on top), scale 1, identity uv mapping.
struct HostTexture {
  Texture t{};
  std::vector<float> texels;
  float3 at(float u, float v) const { return texture_lookup(&t, texels.data(), make_float2(u, v)); }
  float3 texel(int i, int j) const { return texture_texel(&t, texels.data(), i, j); }
};

HostTexture make_texture(int w, int h, int channels, std::vector<float> values,
                         int wrap = TEXTURE_WRAP_REPEAT) {
  HostTexture ht;
  ht.t.width = w;
  ht.t.height = h;
  ht.t.channels = channels;
  ht.t.wrap = wrap;
  ht.t.scale = make_float4(1, 1, 1, 0);
  ht.t.uvmap = make_float4(1, 1, 0, 0);
  ht.texels = std::move(values);
  return ht;
}

std::vector<float> random_values(size_t n, uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(0.05f, 1.0f);
  std::vector<float> v(n);
  for (float& x : v)
    x = u(gen);
  return v;
}

// The uv of the centre of texel (i, j) of a w x h image (row j from the top).
float2 centre(int i, int j, int w, int h) {
  return make_float2((float(i) + 0.5f) / float(w), 1.0f - (float(j) + 0.5f) / float(h));
}

void expect_near3(float3 a, float3 b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

// ---------------------------------------------------------------- rendered planes
// 4 x 4 texels in 2 x 2 blocks; block (bx, by) (by from the image's top) has colour c[2 by + bx].
std::vector<float> block_texels(const float3 c[4], int channels) {
  std::vector<float> v;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      float3 col = c[2 * (j / 2) + i / 2];
      if (channels == 1) {
        v.push_back(col.x);
      } else {
        v.insert(v.end(), {col.x, col.y, col.z});
      }
    }
  return v;
}

std::filesystem::path write_texture(const std::string& name, const std::vector<float>& v,
                                    int channels) {
  RgbImage img;
  img.width = 4;
  img.height = 4;
  for (size_t i = 0; i < v.size(); i += size_t(channels))
    for (int k = 0; k < 3; ++k)
      img.rgb.push_back(v[i + size_t(channels == 3 ? k : 0)]);
  auto f = temp_dir() / name;
  write_exr(f, img);
  return f;
}

TextureDesc texture_desc(const std::filesystem::path& file, int channels, int map) {
  TextureDesc t;
  t.file = file;
  t.where = "test";
  t.channels = channels;
  t.map = map;
  return t;
}

// The block whose constant square holds the whole footprint of pixel (x, y) (its four corners, a
// convex quadrilateral on the plane, inside a convex square), or -1.
int constant_block(const CameraParams& cam, int x, int y) {
  int block = -1;
  for (int c = 0; c < 4; ++c) {
    float3 X;
    test::camera_ray_to_plane(cam, float(x + (c & 1)), float(y + (c >> 1)), &X);
    // texel coordinates: (s w, (1 - t) h)
    float tx = 4.0f * (X.x + 1.0f) * 0.5f, ty = 4.0f * (1.0f - (X.y + 1.0f) * 0.5f);
    int bx = int(std::floor(tx / 2.0f)), by = int(std::floor(ty / 2.0f));
    float fx = tx - 2.0f * float(bx), fy = ty - 2.0f * float(by);
    const float m = 1e-3f;
    if (bx < 0 || bx > 1 || by < 0 || by > 1 || fx < 0.5f + m || fx > 1.5f - m || fy < 0.5f + m ||
        fy > 1.5f - m)
      return -1;
    int b = 2 * by + bx;
    if (block >= 0 && b != block) return -1;
    block = b;
  }
  return block;
}

const float3 kBlockColours[4] = {make_float3(0.9f, 0.2f, 0.1f), make_float3(0.1f, 0.8f, 0.3f),
                                 make_float3(0.3f, 0.3f, 0.9f), make_float3(0.6f, 0.6f, 0.05f)};

} // namespace

TEST(TextureLookup, TexelCentresGiveTheTexelAndMidpointsTheirMean) {
  const int w = 5, h = 3;
  HostTexture ht = make_texture(w, h, 3, random_values(w * h * 3, 1));
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      float2 c = centre(i, j, w, h);
      const float3 t = ht.texel(i, j);
      expect_near3(ht.at(c.x, c.y), t, 1e-6f, "centre");
      // halfway to the right neighbour (wrapping) and to the one below
      float3 right = ht.texel((i + 1) % w, j), below = ht.texel(i, (j + 1) % h);
      expect_near3(ht.at(c.x + 0.5f / w, c.y), (t + right) * 0.5f, 1e-6f, "right");
      expect_near3(ht.at(c.x, c.y - 0.5f / h), (t + below) * 0.5f, 1e-6f, "below");
      // a quarter of the way to the diagonal neighbour: bilinear weights 9/16, 3/16, 3/16, 1/16
      float3 diag = ht.texel((i + 1) % w, (j + 1) % h);
      float3 q = t * (9.0f / 16) + right * (3.0f / 16) + below * (3.0f / 16) + diag * (1.0f / 16);
      expect_near3(ht.at(c.x + 0.25f / w, c.y - 0.25f / h), q, 1e-6f, "quarter");
    }
  // v = 0 is the image's bottom row, u = 0 its left column (pbrt-v4, OBJ).
  expect_near3(ht.at(0.5f / w, 0.5f / h), ht.texel(0, h - 1), 1e-6f, "bottom left");
  expect_near3(ht.at(1.0f - 0.5f / w, 1.0f - 0.5f / h), ht.texel(w - 1, 0), 1e-6f, "top right");
}

TEST(TextureLookup, WrapModes) {
  const int w = 4, h = 2;
  std::vector<float> v = random_values(w * h * 3, 2);
  HostTexture rep = make_texture(w, h, 3, v, TEXTURE_WRAP_REPEAT);
  HostTexture clamp = make_texture(w, h, 3, v, TEXTURE_WRAP_CLAMP);
  HostTexture black = make_texture(w, h, 3, v, TEXTURE_WRAP_BLACK);
  const float2 c = centre(1, 0, w, h);
  for (float shift : {1.0f, -3.0f, 17.0f})
    expect_near3(rep.at(c.x + shift, c.y + shift), rep.at(c.x, c.y), 2e-5f, "repeat");
  // u = 0 sits halfway between the last column's centre and the first's.
  expect_near3(rep.at(0.0f, c.y), (rep.texel(w - 1, 0) + rep.texel(0, 0)) * 0.5f, 1e-6f,
               "repeat seam");
  expect_near3(clamp.at(0.0f, c.y), clamp.texel(0, 0), 1e-6f, "clamp edge");
  expect_near3(clamp.at(-2.5f, c.y), clamp.texel(0, 0), 1e-6f, "clamp far left");
  expect_near3(clamp.at(9.0f, c.y), clamp.texel(w - 1, 0), 1e-6f, "clamp far right");
  expect_near3(black.at(0.0f, c.y), black.texel(0, 0) * 0.5f, 1e-6f, "black edge");
  expect_near3(black.at(-1.0f, c.y), make_float3(0, 0, 0), 0.0f, "black outside");
  expect_near3(black.at(c.x, 3.0f), make_float3(0, 0, 0), 0.0f, "black above");
}

TEST(TextureLookup, UvMappingScaleAndOneChannel) {
  const int w = 3, h = 3;
  HostTexture plain = make_texture(w, h, 3, random_values(w * h * 3, 3));
  HostTexture mapped = plain;
  mapped.t.uvmap = make_float4(2.0f, 0.5f, 0.25f, -0.1f);
  mapped.t.scale = make_float4(2.0f, 3.0f, 0.5f, 0.0f);
  for (float u : {0.1f, 0.37f, 0.8f})
    for (float v : {0.2f, 0.55f, 0.9f}) {
      float3 a = mapped.at(u, v), b = plain.at(2.0f * u + 0.25f, 0.5f * v - 0.1f);
      expect_near3(a, make_float3(2.0f * b.x, 3.0f * b.y, 0.5f * b.z), 1e-5f, "uvmap");
    }
  HostTexture grey = make_texture(w, h, 1, random_values(w * h, 4));
  float3 g = grey.at(0.3f, 0.6f);
  EXPECT_EQ(g.x, g.y);
  EXPECT_EQ(g.x, g.z);
  expect_near3(grey.at(centre(2, 1, w, h).x, centre(2, 1, w, h).y),
               make_float3(grey.texels[5], grey.texels[5], grey.texels[5]), 1e-6f, "grey");
}

TEST(TextureLookup, NonFiniteOrHugeCoordinatesStayInTheImage) {
  const float inf = std::numeric_limits<float>::infinity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int wrap : {TEXTURE_WRAP_REPEAT, TEXTURE_WRAP_CLAMP, TEXTURE_WRAP_BLACK}) {
    HostTexture ht = make_texture(3, 2, 3, random_values(18, 5), wrap);
    for (float u : {nan, inf, -inf, 1e30f, -1e30f, 0.5f})
      for (float v : {nan, inf, 0.25f}) {
        float3 c = ht.at(u, v);
        EXPECT_TRUE(std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z));
        EXPECT_GE(c.x, 0.0f);
        EXPECT_LE(c.x, 1.0f);
      }
  }
}

TEST(TextureLookup, RoughnessMapsToAlpha) {
  EXPECT_FLOAT_EQ(texture_alpha(TEXTURE_MAP_ALPHA_SQUARE, 0.5f), 0.25f);
  EXPECT_FLOAT_EQ(texture_alpha(TEXTURE_MAP_ALPHA_SQRT, 0.25f), 0.5f);
  EXPECT_FLOAT_EQ(texture_alpha(TEXTURE_MAP_VALUE, 0.3f), 0.3f);
  EXPECT_EQ(texture_alpha(TEXTURE_MAP_ALPHA_SQUARE, 2.0f), 1.0f); // Canopy's GGX range
  EXPECT_EQ(texture_alpha(TEXTURE_MAP_VALUE, -0.5f), 0.0f);
  EXPECT_EQ(texture_alpha(TEXTURE_MAP_ALPHA_SQRT, std::numeric_limits<float>::quiet_NaN()), 0.0f);
}

// material_apply_textures interpolates the triangle's uv, clamps the albedo to [0, 1] and maps the
// roughness texture to alpha; an untextured field keeps the material's constant.
TEST(TextureLookup, MaterialTakesItsTexturesAtTheHit) {
  HostTexture rgb = make_texture(
      2, 2, 3, {0.2f, 0.4f, 0.6f, 0.5f, 0.5f, 0.5f, 0.1f, 0.2f, 0.3f, 0.9f, 0.8f, 0.7f});
  rgb.t.scale = make_float4(2.0f, 2.0f, 2.0f, 0.0f);
  HostTexture rough = make_texture(1, 1, 1, {0.6f});
  rough.t.first = int(rgb.texels.size());
  rough.t.map = TEXTURE_MAP_ALPHA_SQUARE;
  std::vector<float> texels = rgb.texels;
  texels.push_back(0.6f);
  std::vector<Texture> textures = {rgb.t, rough.t};
  // triangle 0's uv: the bottom-left texel's centre at every vertex
  std::vector<float2> uv(3, make_float2(0.25f, 0.25f));
  Material m{};
  m.albedo = make_float4(0.5f, 0.5f, 0.5f, 0);
  m.alpha = 0.01f;
  m.albedo_texture = 1;
  Material a = m;
  material_apply_textures(&a, uv.data(), textures.data(), texels.data(), 0, 0.3f, 0.2f);
  // texel (0, 1) = (0.1, 0.2, 0.3) times 2
  expect_near3(xyz_of(a.albedo), make_float3(0.2f, 0.4f, 0.6f), 1e-6f, "albedo");
  EXPECT_EQ(a.alpha, 0.01f);
  uv.assign(3, make_float2(0.75f, 0.25f)); // texel (1, 1) = 0.9, 0.8, 0.7: clamped
  m.alpha_texture = 2;
  material_apply_textures(&m, uv.data(), textures.data(), texels.data(), 0, 0.3f, 0.2f);
  expect_near3(xyz_of(m.albedo), make_float3(1.0f, 1.0f, 1.0f), 0.0f, "clamped");
  EXPECT_FLOAT_EQ(m.alpha, 0.36f);
  // barycentric interpolation: uv(v0) + bu (uv(v1) - uv(v0)) + bv (uv(v2) - uv(v0))
  uv = {make_float2(0, 0), make_float2(1, 0), make_float2(0, 1)};
  float2 p = triangle_uv(uv.data(), 0, 0.3f, 0.6f);
  EXPECT_FLOAT_EQ(p.x, 0.3f);
  EXPECT_FLOAT_EQ(p.y, 0.6f);
}

// 8-bit images are sRGB-decoded unless told otherwise; a one-channel texture of an rgb image is
// the mean of its channels. tests/data/textures/colours.png has texel (0, 0) = (20, 90, 40) / 255.
TEST(TextureImages, EncodingsAndChannels) {
  const auto file = std::filesystem::path(CANOPY_TEST_DATA_DIR) / "textures" / "colours.png";
  const float r = 20.0f / 255, g = 90.0f / 255, b = 40.0f / 255;
  RenderImage srgb = read_render_image(file, "texture", 1 << 20, 3);
  ASSERT_EQ(srgb.width, 8);
  ASSERT_EQ(srgb.height, 8);
  EXPECT_FLOAT_EQ(srgb.values[0], srgb_decode(r));
  EXPECT_FLOAT_EQ(srgb.values[1], srgb_decode(g));
  EXPECT_FLOAT_EQ(srgb.values[2], srgb_decode(b));
  RenderImage lin = read_render_image(file, "texture", 1 << 20, 3, ImageEncoding::Linear);
  EXPECT_FLOAT_EQ(lin.values[1], g);
  RenderImage gam = read_render_image(file, "texture", 1 << 20, 3, ImageEncoding::Gamma, 2.2f);
  EXPECT_FLOAT_EQ(gam.values[2], std::pow(b, 2.2f));
  RenderImage mean = read_render_image(file, "texture", 1 << 20, 1, ImageEncoding::Linear);
  ASSERT_EQ(mean.values.size(), 64u);
  EXPECT_FLOAT_EQ(mean.values[0], (r + g + b) / 3.0f);
  // one image used by two textures with the same channels and encoding is stored once
  TextureDesc t = texture_desc(file, 3, TEXTURE_MAP_VALUE);
  TextureDesc u = t;
  u.scale = make_float3(0.5f, 0.5f, 0.5f);
  TextureDesc f = texture_desc(file, 1, TEXTURE_MAP_ALPHA_SQRT);
  TextureData d = build_texture_data({t, u, f});
  ASSERT_EQ(d.textures.size(), 3u);
  EXPECT_EQ(d.textures[0].first, d.textures[1].first);
  EXPECT_EQ(d.textures[1].scale.x, 0.5f);
  EXPECT_EQ(d.textures[2].first, 64 * 3);
  EXPECT_EQ(d.textures[2].channels, 1);
  EXPECT_EQ(d.textures[2].map, TEXTURE_MAP_ALPHA_SQRT);
  EXPECT_EQ(d.texels.size(), size_t(64 * 4));
}

// A missing, unreadable or non-finite image is one error naming the file.
TEST(TextureImages, BadImagesAreErrorsNamingTheFile) {
  auto dir = temp_dir();
  auto expect_error = [](const TextureDesc& t, const std::string& part) {
    try {
      build_texture_data({t});
      ADD_FAILURE() << "no error for " << t.file;
    } catch (const SceneError& e) {
      std::string msg = e.what();
      EXPECT_NE(msg.find(t.file.string()), std::string::npos) << msg;
      EXPECT_NE(msg.find(part), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  };
  expect_error(texture_desc(dir / "missing.png", 3, 0), "cannot read the texture");
  std::ofstream(dir / "junk.png") << "not an image";
  expect_error(texture_desc(dir / "junk.png", 3, 0), "cannot read the texture");
  RgbImage img;
  img.width = 2;
  img.height = 1;
  img.rgb = {0.5f, 0.5f, 0.5f, 0.5f, std::numeric_limits<float>::quiet_NaN(), 0.5f};
  write_exr(dir / "nan.exr", img);
  expect_error(texture_desc(dir / "nan.exr", 3, 0), "texel (1, 0) is nan");
  img.rgb[4] = -1.0f;
  write_exr(dir / "neg.exr", img);
  expect_error(texture_desc(dir / "neg.exr", 1, 0), "texel (1, 0) is -1");
  // A PNG cut short: libpng's own "libpng error: ..." line is not printed (it becomes the reason
  // at the end of the one-line error).
  RgbImage grey;
  grey.width = grey.height = 8;
  grey.rgb.assign(8 * 8 * 3, 0.5f);
  write_png(dir / "whole.png", grey);
  std::ifstream whole(dir / "whole.png", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
  std::ofstream(dir / "cut.png", std::ios::binary) << bytes.substr(0, 40);
  testing::internal::CaptureStderr();
  expect_error(texture_desc(dir / "cut.png", 3, 0), "cannot read the texture (");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

// Kernels hold texture code only for scenes with a textured material.
TEST(TextureFeatures, OnlyScenesWithTexturesCompileThem) {
  Scene s = test::uv_plane_scene(diffuse_material("plain", make_float3(0.5f, 0.5f, 0.5f)), 8);
  EXPECT_FALSE(scene_features(s, SAMPLER_TREE).textures);
  EXPECT_NE(scene_features(s, SAMPLER_TREE).build_options().find("-DHAS_TEXTURES=0"),
            std::string::npos);
  s.materials[0].gpu.alpha_texture = 1;
  EXPECT_TRUE(scene_features(s, SAMPLER_TREE).textures);
}

// A diffuse plane with a block texture under a distant light: every pixel inside a block's constant
// square is exactly that block's rho / pi E cos(theta), for every light sampler, at depth 1 and 2;
// the others lie between the darkest and brightest block.
TEST(TextureRender, DiffusePlaneUnderTheSunIsExactInsideEachBlock) {
  const auto file = write_texture("blocks.exr", block_texels(kBlockColours, 3), 3);
  const float3 E = make_float3(3.0f, 2.0f, 5.0f);
  const float3 travel = make_float3(0.3f, -0.6f, -0.8f);
  const float cos_t = -normalize(travel).z;
  for (const char* sampler : {"power", "tree", "tree-split", "exhaustive", "brdf-mis"})
    for (int depth : {1, 2}) {
      SCOPED_TRACE(std::string(sampler) + " depth " + std::to_string(depth));
      MaterialDesc m = diffuse_material("blocks", make_float3(0, 0, 0));
      m.gpu.albedo_texture = 1;
      Scene scene = test::uv_plane_scene(m, 48);
      scene.textures.push_back(texture_desc(file, 3, TEXTURE_MAP_VALUE));
      scene.infinite_lights.push_back(test::distant_light(travel, E));
      scene.integrator.max_depth = depth;
      Film film = test::render_lit_plane(scene, sampler, 4);
      CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
      int seen[4] = {0, 0, 0, 0};
      for (int y = 0; y < film.height; ++y)
        for (int x = 0; x < film.width; ++x) {
          size_t p = size_t(y) * size_t(film.width) + size_t(x);
          const double n = film.sum[p].w;
          const float3 got = make_float3(float(film.sum[p].x / n), float(film.sum[p].y / n),
                                         float(film.sum[p].z / n));
          int b = constant_block(cam, x, y);
          if (b >= 0) {
            ++seen[b];
            const float3 expect = kBlockColours[b] * E * (cos_t / kPi);
            EXPECT_NEAR(got.x, expect.x, 2e-6f * expect.x) << x << "," << y << " block " << b;
            EXPECT_NEAR(got.y, expect.y, 2e-6f * expect.y) << x << "," << y << " block " << b;
            EXPECT_NEAR(got.z, expect.z, 2e-6f * expect.z) << x << "," << y << " block " << b;
          } else {
            const float3 lo = make_float3(0.1f, 0.2f, 0.05f) * E * (cos_t / kPi);
            const float3 hi = make_float3(0.9f, 0.8f, 0.9f) * E * (cos_t / kPi);
            EXPECT_GE(got.x, lo.x * 0.999f);
            EXPECT_LE(got.x, hi.x * 1.001f);
            EXPECT_GE(got.z, lo.z * 0.999f);
            EXPECT_LE(got.z, hi.z * 1.001f);
          }
        }
      for (int b = 0; b < 4; ++b)
        EXPECT_GT(seen[b], 30) << "block " << b;
    }
}

// A plastic plane with block albedo and block roughness textures under a point light: inside each
// block's constant square, f(wo, wi) cos I / d^2 of the block's material, box-filtered over the
// pixel (a 16 x 16 midpoint rule; its distance to a 4 x 4 rule and 5 standard errors bound the
// tolerance). The textured alpha must reach every place the BSDF is evaluated: light_pick's light
// samples, and the BRDF-oriented cut and samples of brdf-mis and brdf-oriented.
TEST(TextureRender, GlossyPlaneTakesTheTexturedAlbedoAndRoughnessEverywhere) {
  const float3 rough[4] = {make_float3(0.3f, 0, 0), make_float3(0.5f, 0, 0),
                           make_float3(0.4f, 0, 0), make_float3(0.7f, 0, 0)};
  const auto albedo_file = write_texture("albedo.exr", block_texels(kBlockColours, 3), 3);
  const auto rough_file = write_texture("rough.exr", block_texels(rough, 1), 1);
  const float3 I = make_float3(4.0f, 4.0f, 4.0f), pl = make_float3(0.2f, 0.1f, 1.5f);
  for (const char* sampler : {"power", "tree", "exhaustive", "brdf-mis", "brdf-oriented"}) {
    SCOPED_TRACE(sampler);
    MaterialDesc m =
        plastic_material("worn", make_float3(0, 0, 0), make_float3(1, 1, 1), 0.5f, 1.5f);
    m.gpu.albedo_texture = 1;
    m.gpu.alpha_texture = 2;
    Scene scene = test::uv_plane_scene(m, 32);
    scene.textures.push_back(texture_desc(albedo_file, 3, TEXTURE_MAP_VALUE));
    scene.textures.push_back(texture_desc(rough_file, 1, TEXTURE_MAP_ALPHA_SQUARE));
    scene.lights.push_back(test::point_light(pl, I));
    // 256 spp: brdf-mis's rare large samples (also on an untextured plane) make the variance of
    // 16 samples an underestimate.
    Film film = test::render_lit_plane(scene, sampler, 256);
    CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
    int checked = 0;
    for (int y = 0; y < film.height; ++y)
      for (int x = 0; x < film.width; ++x) {
        int b = constant_block(cam, x, y);
        if (b < 0) continue;
        Material mb = m.gpu;
        mb.albedo = f4_from3(kBlockColours[b], 0.0f);
        mb.alpha = rough[b].x * rough[b].x;
        mb.albedo_texture = mb.alpha_texture = 0;
        auto radiance = [&](float fx, float fy) {
          float3 X;
          float3 d = test::camera_ray_to_plane(cam, fx, fy, &X);
          float3 to = pl - X;
          float d2 = dot(to, to);
          float3 wi = to * (1.0f / std::sqrt(d2));
          return bsdf_eval(&mb, d * -1.0f, wi) * I * (wi.z / d2);
        };
        const float3 ref = test::pixel_average(radiance, x, y, 16);
        const float3 coarse = test::pixel_average(radiance, x, y, 4);
        size_t p = size_t(y) * size_t(film.width) + size_t(x);
        double n = film.sum[p].w;
        double comps[3][3] = {{film.sum[p].x, film.sumsq[p].x, ref.x - coarse.x},
                              {film.sum[p].y, film.sumsq[p].y, ref.y - coarse.y},
                              {film.sum[p].z, film.sumsq[p].z, ref.z - coarse.z}};
        float refs[3] = {ref.x, ref.y, ref.z};
        for (int k = 0; k < 3; ++k) {
          double mean = comps[k][0] / n;
          double var = std::max(0.0, comps[k][1] / n - mean * mean) * n / (n - 1.0);
          double bound = 5.0 * std::sqrt(var / n) + std::fabs(comps[k][2]) + 1e-5 * refs[k];
          EXPECT_NEAR(mean, refs[k], bound) << x << "," << y << " block " << b << " ch " << k;
        }
        ++checked;
      }
    EXPECT_GT(checked, 100);
  }
}
