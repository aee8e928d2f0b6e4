// EXR files through OpenEXR: float RGB with string attributes out, any scanline or tiled EXR in.
#include "image/image_file.h"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <fmt/format.h>

#include <algorithm>
#include <thread>

namespace canopy {

namespace {

// OpenEXR compresses and decompresses blocks of lines on a thread pool; it has none by default.
void use_all_cores() {
  static const bool once = [] {
    Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
    return true;
  }();
  (void)once;
}

// The channels read, in this order: R, G, B, A where present (as OpenImageIO orders them), then
// the rest by name; a file with Y alone (luminance) is one channel.
std::vector<std::string> channel_order(const Imf::ChannelList& list) {
  std::vector<std::string> out;
  for (const char* c : {"R", "G", "B", "A"})
    if (list.findChannel(c)) out.push_back(c);
  for (auto it = list.begin(); it != list.end(); ++it)
    if (std::find(out.begin(), out.end(), it.name()) == out.end()) out.push_back(it.name());
  return out;
}

} // namespace

bool has_exr_signature(const std::string& bytes) {
  return bytes.size() >= 4 && bytes.compare(0, 4, "\x76\x2f\x31\x01") == 0;
}

DecodedImage read_exr_file(const std::filesystem::path& file, uint64_t max_pixels) {
  use_all_cores();
  try {
    Imf::InputFile in(file.c_str());
    const Imf::Header& h = in.header();
    const Imath::Box2i data = h.dataWindow(), display = h.displayWindow();
    DecodedImage img;
    img.width = data.max.x - data.min.x + 1;
    img.height = data.max.y - data.min.y + 1;
    if (img.width < 1 || img.height < 1) throw ImageFileError("an empty data window");
    if (uint64_t(img.width) * uint64_t(img.height) > max_pixels)
      throw ImageTooLarge(img.width, img.height);
    img.window = {data.min.x - display.min.x, data.min.y - display.min.y,
                  display.max.x - display.min.x + 1, display.max.y - display.min.y + 1};
    img.floating = true;
    const std::vector<std::string> names = channel_order(h.channels());
    img.channels = int(names.size());
    if (img.channels == 0) throw ImageFileError("no channels");
    const size_t nc = names.size(), w = size_t(img.width);
    img.pixels.assign(w * size_t(img.height) * nc, 0.0f);
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < nc; ++c)
      fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, img.pixels.data() + c, data,
                                           nc * sizeof(float), w * nc * sizeof(float)));
    in.setFrameBuffer(fb);
    in.readPixels(data.min.y, data.max.y);
    // String attributes, and numbers as text (another tool may write canopy:spp as an int).
    for (auto it = h.begin(); it != h.end(); ++it) {
      const Imf::Attribute& a = it.attribute();
      if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
        img.attributes.emplace_back(it.name(), s->value());
      else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
        img.attributes.emplace_back(it.name(), fmt::format("{}", i->value()));
      else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a))
        img.attributes.emplace_back(it.name(), fmt::format("{}", f->value()));
      else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a))
        img.attributes.emplace_back(it.name(), fmt::format("{}", d->value()));
    }
    return img;
  } catch (const ImageFileError&) {
    throw;
  } catch (const std::exception& e) {
    // OpenEXR's messages start with the file name, which the caller gives.
    std::string why = e.what();
    const std::string name = file.string();
    if (why.rfind(name, 0) == 0) why = why.substr(std::min(why.size(), name.size() + 2));
    throw ImageFileError(why.substr(0, why.find('\n')));
  }
}

void write_exr_file(const std::filesystem::path& file, int width, int height, const float* rgb,
                    const ImageAttributes& attributes, const ImageWindow& window) {
  use_all_cores();
  try {
    const Imath::Box2i display(Imath::V2i(0, 0),
                               Imath::V2i(window.full_width - 1, window.full_height - 1));
    const Imath::Box2i data(Imath::V2i(window.x, window.y),
                            Imath::V2i(window.x + width - 1, window.y + height - 1));
    Imf::Header h(display, data);
    h.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B"})
      h.channels().insert(c, Imf::Channel(Imf::FLOAT));
    for (const auto& [k, v] : attributes)
      h.insert(k, Imf::StringAttribute(v));
    Imf::OutputFile out(file.c_str(), h);
    const size_t w = size_t(width);
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < 3; ++c)
      fb.insert(
          std::string(1, "RGB"[c]),
          Imf::Slice::Make(Imf::FLOAT, rgb + c, data, 3 * sizeof(float), w * 3 * sizeof(float)));
    out.setFrameBuffer(fb);
    out.writePixels(height);
  } catch (const std::exception& e) {
    throw ImageFileError(std::string(e.what()).substr(0, std::string(e.what()).find('\n')));
  }
}

} // namespace canopy
