// Shading normals (OBJ vn) end to end: the two standard fixes of cl/shading.h and
// cl/integrator/ hold in rendered images.
// - No light leaks: a plane whose vertex normals lean far over, lit only from below, renders
//   exactly black from above, for diffuse and glossy materials (reflection is decided by the
//   geometric normal, not the interpolated one).
// - No black fringes: seen at a grazing angle with vertex normals leaning away from the camera
//   (wo below the interpolated normal's horizon), every pixel of a plane lit from above is lit
//   (the shading normal is tilted back until wo's mirror direction is above the surface).
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace canopy;

namespace {

// A 4 x 4 plane at z = 0 (winding normal +z) whose four vertex normals all lean by ~65 degrees
// towards direction (lx, ly) in the plane.
std::filesystem::path write_tilted_plane(const std::string& name, float lx, float ly) {
  auto dir = std::filesystem::temp_directory_path() / "canopy-shading-normals";
  std::filesystem::create_directories(dir);
  auto path = dir / (name + ".obj");
  std::ofstream f(path);
  f << "v -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\n";
  f << "vn " << lx << " " << ly << " 0.45\nvn " << lx << " " << ly << " 0.45\n";
  f << "vn " << lx * 0.8f << " " << ly * 1.1f << " 0.4\nvn " << lx << " " << ly << " 0.5\n";
  f << "f 1//1 2//2 3//3\nf 1//1 3//3 4//4\n";
  return path;
}

Film render_plane(const std::filesystem::path& obj, const std::string& material_json,
                  const std::string& camera_json, const std::string& lights_json) {
  std::string json = R"({ "camera": )" + camera_json + R"(,
    "film": { "width": 24, "height": 18 }, "integrator": { "max_depth": 3 },
    "materials": [ )" +
                     material_json +
                     R"( ],
    "shapes": [ { "type": "obj", "file": ")" +
                     obj.filename().string() + R"(", "material": "m" } ],
    "lights": )" + lights_json +
                     "}";
  Scene s = load_scene_from_string(json, "shading-normals", obj.parent_path());
  EXPECT_FALSE(s.shading_normals.empty());
  ClRuntime rt;
  Renderer r(rt, s, RendererOptions{});
  RenderSettings rs;
  rs.spp = 64;
  rs.seed = 7;
  Film film = r.render(rs);
  EXPECT_EQ(r.stats().nonfinite_samples, 0u);
  return film;
}

const char* kMaterials[] = {
    R"({ "name": "m", "albedo": 0.8 })",
    R"({ "name": "m", "type": "conductor", "metal": "gold", "roughness": 0.3 })",
    R"({ "name": "m", "type": "conductor", "metal": "silver", "roughness": 0 })",
    R"({ "name": "m", "type": "plastic", "albedo": 0.5, "roughness": 0.05 })",
};

} // namespace

class ShadingNormals : public ::testing::TestWithParam<int> {};
// Not the perfect mirror: it sends each pixel's ray into one grazing direction that misses the
// light, so its pixels are black whatever the normals, and it has no fringe to test.
class ShadingNormalFringes : public ::testing::TestWithParam<int> {};

TEST_P(ShadingNormals, NoLightLeaksThroughASurface) {
  // Normals lean towards +x; the lights are below the plane (the quad hidden under it, the point
  // off to +x where the leaning shading normals face it).
  auto obj = write_tilted_plane("leak", 0.9f, 0.0f);
  Film f = render_plane(
      obj, kMaterials[GetParam()],
      R"({ "position": [0, -0.5, 6], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 40 })",
      R"([ { "type": "point", "position": [3, 0.2, -0.3], "intensity": 50 },
           { "type": "quad", "corner": [-1, -1, -0.5], "edge1": [2, 0, 0], "edge2": [0, 2, 0],
             "radiance": 20, "two_sided": true } ])");
  double total = 0;
  for (const double4& s : f.sum)
    total += s.x + s.y + s.z;
  EXPECT_EQ(total, 0.0);
}

TEST_P(ShadingNormalFringes, NoBlackFringesAtGrazingViews) {
  // The camera looks along +y at 15 degrees above the plane; the normals lean towards +y, away
  // from it, so the interpolated normal puts wo below its horizon everywhere. A large light
  // above lights every point.
  auto obj = write_tilted_plane("fringe", 0.0f, 0.9f);
  Film f = render_plane(
      obj, kMaterials[GetParam()],
      R"({ "position": [0, -7, 1.9], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 20 })",
      R"([ { "type": "quad", "corner": [-6, -8, 4], "edge1": [12, 0, 0], "edge2": [0, 16, 0],
             "radiance": 5, "two_sided": true } ])");
  // Pixels whose camera rays meet the plane well inside its edges (|x|, |y| < 1.6 at the
  // pixel centre): every one of them must have received light.
  Camera cam;
  cam.position = make_float3(0, -7, 1.9f);
  cam.look_at = make_float3(0, 0, 0);
  cam.up = make_float3(0, 0, 1);
  cam.fov_y_deg = 20.0f;
  CameraParams cp = make_camera_params(cam, f.width, f.height);
  int plane_pixels = 0, black = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      float3 o = xyz_of(cp.origin);
      float3 d = normalize(xyz_of(cp.lower_left) + xyz_of(cp.du) * (float(x) + 0.5f) +
                           xyz_of(cp.dv) * (float(y) + 0.5f));
      if (!(d.z < 0)) continue;
      float3 p = o + d * (-o.z / d.z);
      if (std::fabs(p.x) > 1.6f || std::fabs(p.y) > 1.6f) continue;
      ++plane_pixels;
      const double4& s = f.sum[size_t(y) * size_t(f.width) + size_t(x)];
      black += !(s.x + s.y + s.z > 0.0);
    }
  EXPECT_GT(plane_pixels, 20);
  EXPECT_EQ(black, 0) << "of " << plane_pixels << " plane pixels";
}

std::string material_name(const ::testing::TestParamInfo<int>& p) {
  static const char* names[] = {"diffuse", "conductor", "mirror", "plastic"};
  return names[p.param];
}

INSTANTIATE_TEST_SUITE_P(Materials, ShadingNormals, ::testing::Values(0, 1, 2, 3), material_name);
INSTANTIATE_TEST_SUITE_P(Materials, ShadingNormalFringes, ::testing::Values(0, 1, 3),
                         material_name);
