// The public entry points of the pbrt-v4 reader (scene/pbrt_reader.h).
#include "scene/pbrt/reader.h"
#include "scene/pbrt_reader.h"

#include <fmt/format.h>

#include <functional>
#include <new>
#include <stdexcept>

namespace canopy {

namespace {

Scene load(const std::string& text, const std::string& name, const std::filesystem::path& dir,
           const std::filesystem::path* file, const SceneLoadOptions& options) {
  Scene scene;
  scene.path = name;
  // pbrt-v4's defaults: a 1280 x 720 film and a diffuse material of reflectance 0.5.
  scene.film.width = 1280;
  scene.film.height = 720;
  scene.materials.push_back(diffuse_material("default", make_float3(0.5f, 0.5f, 0.5f)));
  pbrt::Reader r(scene, name, dir, options);
  if (file)
    r.run_file(*file, name, nullptr);
  else
    r.run_text(text, name, dir);
  r.finish();
  return scene;
}

Scene guarded(const std::string& name, const std::function<Scene()>& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  } catch (const std::length_error&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  }
}

} // namespace

Scene load_pbrt_scene(const std::filesystem::path& file, const SceneLoadOptions& options) {
  std::string name = printable(file.string(), 1024);
  Scene s = guarded(name, [&] { return load({}, name, file.parent_path(), &file, options); });
  s.path = file;
  return s;
}

Scene load_pbrt_scene_from_string(const std::string& text, const std::string& name,
                                  const std::filesystem::path& base_dir,
                                  const SceneLoadOptions& options) {
  return guarded(name, [&] { return load(text, name, base_dir, nullptr, options); });
}

} // namespace canopy
