// Partial renders and their merge (docs/distributed.md). Every image `canopy render` writes is the
// mean of the sample indices [sample_begin, sample_end) of each pixel of a window of the film (the
// whole film and [0, spp) unless --crop or --samples say otherwise). Its EXR holds the window's
// pixels as the data window of the film's display window, and the facts a merge checks as canopy:*
// attributes: the sample range, the window, the seed, the film size, a hash of the scene file and
// Canopy's version. A sample's random numbers depend only on (seed, pixel, sample index), so the
// images of disjoint ranges and windows, merged by sample count, are the image of one render.
#pragma once

#include "image/image_io.h"

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace canopy {

// Bad or inconsistent input to a merge: one line, naming the file(s).
class MergeError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct PartialInfo {
  std::string scene;      // the scene file, as given on the command line
  std::string scene_hash; // scene_file_hash of it
  std::string version;    // Canopy's (canopy_version())
  uint32_t seed = 0;
  int film_width = 0, film_height = 0;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;   // the window [x0, x1) x [y0, y1) of the film
  int sample_begin = 0, sample_end = 0; // the sample indices [begin, end) of each window pixel

  int samples() const { return sample_end - sample_begin; }
};

struct PartialImage {
  PartialInfo info;
  RgbImage pixels; // the window's, (x1 - x0) x (y1 - y0)
};

// Canopy's version, as recorded in its images.
std::string canopy_version();
// 64-bit FNV-1a of the file's bytes, as 16 hex digits. Throws std::runtime_error naming the file.
std::string scene_file_hash(const std::filesystem::path& file);

// The canopy:* attributes of `info` (also used to describe a merged image).
std::vector<std::pair<std::string, std::string>> partial_metadata(const PartialInfo& info);

// Writes `pixels` (the window's) as an EXR whose data window is info's window of the film, with
// partial_metadata(info) and `extra` attributes; atomic like write_exr.
void write_partial_exr(const std::filesystem::path& file, const RgbImage& pixels,
                       const PartialInfo& info,
                       const std::vector<std::pair<std::string, std::string>>& extra = {});

// Reads an image written by write_partial_exr. Throws MergeError (one line naming the file) when
// it is missing, unreadable or truncated, or lacks or contradicts the canopy:* attributes.
PartialImage read_partial_exr(const std::filesystem::path& file);

struct MergeResult {
  PartialInfo info; // the film's; a sample range and seed only when `uniform` (see below)
  RgbImage image;   // the whole film: per pixel the sample-count-weighted mean of the inputs
  std::vector<uint32_t> samples; // per pixel, the samples merged into it
  uint32_t min_samples = 0, max_samples = 0;
  uint64_t short_pixels = 0; // pixels with fewer samples than the most covered one
  // Every pixel holds the same samples, of one seed, forming one range: the result is itself a
  // partial image of the whole film (info.sample_begin/end) and can be merged again.
  bool uniform = false;
  bool mixed_versions = false; // inputs of different Canopy versions (merged, with a warning)
};

// Merges partial images by sample count, one at a time, so that only one image and the film's
// sums are in memory at once. add() throws MergeError (one line; `name` labels the image) for an
// image of another scene (by hash) or film size than the first, or that holds samples (same seed,
// overlapping ranges) of pixels an earlier image holds.
class PartialMerger {
public:
  void add(const PartialImage& part, const std::string& name);
  MergeResult finish() const; // throws MergeError if nothing was added

private:
  std::vector<PartialInfo> infos_;
  std::vector<std::string> names_;
  std::vector<double> sum_;     // per film pixel and channel: samples x mean
  std::vector<uint64_t> count_; // per film pixel: samples
  std::vector<int> lo_, hi_;    // per film pixel: the smallest first and largest end index
  bool mixed_versions_ = false;
};

// PartialMerger over `parts`, labelled by `names`.
MergeResult merge_partials(const std::vector<PartialImage>& parts,
                           const std::vector<std::string>& names);

} // namespace canopy
