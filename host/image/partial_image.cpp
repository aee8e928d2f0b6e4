#include "image/partial_image.h"

#include "scene/scene.h" // printable

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#ifndef CANOPY_VERSION
#define CANOPY_VERSION "unknown"
#endif

namespace canopy {

namespace {

// Attribute names, shared by writer and reader.
constexpr const char* kScene = "canopy:scene";
constexpr const char* kSceneHash = "canopy:scene_hash";
constexpr const char* kVersion = "canopy:version";
constexpr const char* kSeed = "canopy:seed";
constexpr const char* kFilm = "canopy:film";       // "WxH"
constexpr const char* kCrop = "canopy:crop";       // "x0,y0,x1,y1"
constexpr const char* kSamples = "canopy:samples"; // "A:B"

// Integers separated by `sep`, exactly `n` of them, each in [lo, hi]; false if `text` is not that.
bool parse_ints(const std::string& text, char sep, size_t n, long long lo, long long hi,
                std::vector<long long>& out) {
  out.clear();
  size_t pos = 0;
  while (out.size() < n) {
    size_t end = out.size() + 1 < n ? text.find(sep, pos) : text.size();
    if (end == std::string::npos) return false;
    std::string part = text.substr(pos, end - pos);
    if (part.empty() || part.size() > 19 ||
        part.find_first_not_of("0123456789", part[0] == '-' ? 1 : 0) != std::string::npos)
      return false;
    long long v = std::stoll(part);
    if (v < lo || v > hi) return false;
    out.push_back(v);
    pos = end + 1;
  }
  return true;
}

std::string window_text(int x0, int y0, int x1, int y1) {
  return fmt::format("[{}, {}) x [{}, {})", x0, x1, y0, y1);
}

} // namespace

std::string canopy_version() {
  return CANOPY_VERSION;
}

std::string scene_file_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read the scene file", file.string()));
  uint64_t h = 14695981039346656037ull; // FNV-1a, 64 bits
  char buf[1 << 16];
  while (in.read(buf, sizeof(buf)) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= uint64_t(uint8_t(buf[i]));
      h *= 1099511628211ull;
    }
  }
  return fmt::format("{:016x}", h);
}

std::vector<std::pair<std::string, std::string>> partial_metadata(const PartialInfo& info) {
  return {{kScene, info.scene},
          {kSceneHash, info.scene_hash},
          {kVersion, info.version},
          {kSeed, std::to_string(info.seed)},
          {kFilm, fmt::format("{}x{}", info.film_width, info.film_height)},
          {kCrop, fmt::format("{},{},{},{}", info.x0, info.y0, info.x1, info.y1)},
          {kSamples, fmt::format("{}:{}", info.sample_begin, info.sample_end)}};
}

void write_partial_exr(const std::filesystem::path& file, const RgbImage& pixels,
                       const PartialInfo& info,
                       const std::vector<std::pair<std::string, std::string>>& extra) {
  auto meta = partial_metadata(info);
  meta.insert(meta.end(), extra.begin(), extra.end());
  write_exr(file, pixels, meta, ImageWindow{info.x0, info.y0, info.film_width, info.film_height});
}

PartialImage read_partial_exr(const std::filesystem::path& file) {
  const std::string name = printable(file.string(), 1024);
  auto fail = [&](const std::string& problem) -> MergeError {
    return MergeError(fmt::format("{}: {}", name, problem));
  };
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw fail("no such file");
  DecodedImage img;
  try {
    img = read_image_file(file);
  } catch (const ImageFileError& e) {
    throw fail(fmt::format("cannot read ({})", printable(e.what(), 300)));
  }
  auto attr = [&](const char* key) {
    std::string v;
    for (const auto& [k, value] : img.attributes)
      if (k == key) v = value;
    if (v.empty())
      throw fail(fmt::format("not a Canopy render (no {} attribute; a merge of unequal sample "
                             "coverage cannot be merged again)",
                             key));
    return v;
  };
  // The sample range first: a merge of unequal coverage has everything else.
  const std::string samples = attr(kSamples);
  PartialImage p;
  PartialInfo& info = p.info;
  info.scene = attr(kScene);
  info.scene_hash = attr(kSceneHash);
  info.version = attr(kVersion);
  std::vector<long long> v;
  const long long kSide = std::numeric_limits<int>::max();
  if (!parse_ints(attr(kSeed), ',', 1, 0, 0xffffffffLL, v))
    throw fail(fmt::format("bad {} '{}'", kSeed, printable(attr(kSeed), 100)));
  info.seed = uint32_t(v[0]);
  if (!parse_ints(attr(kFilm), 'x', 2, 1, kSide, v))
    throw fail(fmt::format("bad {} '{}' (want WxH)", kFilm, printable(attr(kFilm), 100)));
  info.film_width = int(v[0]), info.film_height = int(v[1]);
  if (!parse_ints(attr(kCrop), ',', 4, 0, kSide, v) || v[0] >= v[2] || v[1] >= v[3] ||
      v[2] > info.film_width || v[3] > info.film_height)
    throw fail(fmt::format("bad {} '{}' (want x0,y0,x1,y1 inside the {}x{} film)", kCrop,
                           printable(attr(kCrop), 100), info.film_width, info.film_height));
  info.x0 = int(v[0]), info.y0 = int(v[1]), info.x1 = int(v[2]), info.y1 = int(v[3]);
  if (!parse_ints(samples, ':', 2, 0, kSide, v) || v[0] >= v[1])
    throw fail(fmt::format("bad {} '{}' (want A:B, A < B)", kSamples, printable(samples, 100)));
  info.sample_begin = int(v[0]), info.sample_end = int(v[1]);
  if (img.window.x != info.x0 || img.window.y != info.y0 || img.width != info.x1 - info.x0 ||
      img.height != info.y1 - info.y0 || img.channels < 3)
    throw fail(fmt::format("its pixels ({}x{} at {}, {}, {} channels) are not the window {} of "
                           "{}",
                           img.width, img.height, img.window.x, img.window.y, img.channels,
                           window_text(info.x0, info.y0, info.x1, info.y1), kCrop));
  const size_t n = size_t(img.width) * size_t(img.height);
  const std::vector<float>& all = img.pixels;
  p.pixels.width = img.width;
  p.pixels.height = img.height;
  p.pixels.rgb.resize(3 * n);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) {
      float x = all[i * size_t(img.channels) + c];
      if (!std::isfinite(x))
        throw fail(fmt::format("pixel ({}, {}) is not finite", info.x0 + int(i % size_t(img.width)),
                               info.y0 + int(i / size_t(img.width))));
      p.pixels.rgb[3 * i + c] = x;
    }
  return p;
}

void PartialMerger::add(const PartialImage& part, const std::string& name) {
  const PartialInfo& a = part.info;
  if (!infos_.empty()) {
    const PartialInfo& ref = infos_[0];
    if (a.scene_hash != ref.scene_hash)
      throw MergeError(fmt::format("{}: rendered from scene {} (hash {}), {} from {} (hash {})",
                                   name, printable(a.scene, 300), a.scene_hash, names_[0],
                                   printable(ref.scene, 300), ref.scene_hash));
    if (a.film_width != ref.film_width || a.film_height != ref.film_height)
      throw MergeError(fmt::format("{}: film {}x{}, {} has {}x{}", name, a.film_width,
                                   a.film_height, names_[0], ref.film_width, ref.film_height));
  }
  // The same samples (seed and index) of the same pixel twice would count them twice.
  for (size_t i = 0; i < infos_.size(); ++i) {
    const PartialInfo& b = infos_[i];
    int s0 = std::max(a.sample_begin, b.sample_begin), s1 = std::min(a.sample_end, b.sample_end);
    int x0 = std::max(a.x0, b.x0), x1 = std::min(a.x1, b.x1);
    int y0 = std::max(a.y0, b.y0), y1 = std::min(a.y1, b.y1);
    if (a.seed == b.seed && s0 < s1 && x0 < x1 && y0 < y1)
      throw MergeError(fmt::format("{} and {} both hold samples [{}, {}) of seed {} for pixels {}",
                                   names_[i], name, s0, s1, a.seed, window_text(x0, y0, x1, y1)));
  }
  const size_t W = size_t(a.film_width);
  if (infos_.empty()) {
    const size_t npix = W * size_t(a.film_height);
    sum_.assign(3 * npix, 0.0);
    count_.assign(npix, 0);
    lo_.assign(npix, std::numeric_limits<int>::max());
    hi_.assign(npix, 0);
  }
  mixed_versions_ = mixed_versions_ || (!infos_.empty() && a.version != infos_[0].version);
  infos_.push_back(a);
  names_.push_back(name);
  const double n = double(a.samples());
  for (int y = a.y0; y < a.y1; ++y)
    for (int x = a.x0; x < a.x1; ++x) {
      size_t f = size_t(y) * W + size_t(x);
      size_t w = size_t(y - a.y0) * size_t(a.x1 - a.x0) + size_t(x - a.x0);
      for (size_t c = 0; c < 3; ++c)
        sum_[3 * f + c] += n * double(part.pixels.rgb[3 * w + c]);
      count_[f] += uint64_t(a.samples());
      lo_[f] = std::min(lo_[f], a.sample_begin);
      hi_[f] = std::max(hi_[f], a.sample_end);
    }
}

MergeResult PartialMerger::finish() const {
  if (infos_.empty()) throw MergeError("merge: no input images");
  MergeResult r;
  const PartialInfo& ref = infos_[0];
  const int W = ref.film_width, H = ref.film_height;
  const size_t npix = size_t(W) * size_t(H);
  bool one_seed = true;
  for (const PartialInfo& a : infos_)
    one_seed = one_seed && a.seed == ref.seed;
  r.mixed_versions = mixed_versions_;
  r.image.width = W;
  r.image.height = H;
  r.image.rgb.assign(3 * npix, 0.0f);
  r.samples.resize(npix);
  uint64_t cmin = std::numeric_limits<uint64_t>::max(), cmax = 0;
  for (size_t f = 0; f < npix; ++f) {
    cmin = std::min(cmin, count_[f]);
    cmax = std::max(cmax, count_[f]);
    if (count_[f] > 0)
      for (size_t c = 0; c < 3; ++c)
        r.image.rgb[3 * f + c] = float(sum_[3 * f + c] / double(count_[f]));
  }
  for (size_t f = 0; f < npix; ++f) {
    r.samples[f] = uint32_t(std::min<uint64_t>(count_[f], 0xffffffffu));
    if (count_[f] < cmax) ++r.short_pixels;
  }
  r.min_samples = uint32_t(std::min<uint64_t>(cmin, 0xffffffffu));
  r.max_samples = uint32_t(std::min<uint64_t>(cmax, 0xffffffffu));
  // One contiguous range of one seed in every pixel: itself a partial image of the whole film.
  r.uniform = one_seed && cmin == cmax && cmin > 0;
  for (size_t f = 0; r.uniform && f < npix; ++f)
    r.uniform = lo_[f] == lo_[0] && uint64_t(hi_[f] - lo_[f]) == count_[f];
  r.info = ref;
  r.info.x0 = r.info.y0 = 0;
  r.info.x1 = W;
  r.info.y1 = H;
  r.info.sample_begin = r.uniform ? lo_[0] : 0;
  r.info.sample_end = r.uniform ? hi_[0] : 0;
  return r;
}

MergeResult merge_partials(const std::vector<PartialImage>& parts,
                           const std::vector<std::string>& names) {
  PartialMerger m;
  for (size_t i = 0; i < parts.size(); ++i)
    m.add(parts[i], names[i]);
  return m.finish();
}

} // namespace canopy
