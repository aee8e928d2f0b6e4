// The camera of a pbrt-v4 file: the Camera directive, and the camera frame, field of view and
// scene origin fixed when the world begins.
#include "scene/pbrt/reader.h"
#include "scene/pbrt/transforms.h"

#include <fmt/format.h>

#include <cmath>

namespace canopy::pbrt {

// The format page, "Cameras": the CTM at the Camera directive is camera-from-world, and the
// "camera" coordinate system is its inverse.
void Reader::camera(const Token& d, Params& p, const std::string& type) {
  if (type != "perspective")
    warn(d.loc, fmt::format("Camera \"{}\": read as \"perspective\" (its projection ignored)",
                            printable(type)));
  camera_set_ = true;
  camera_loc_ = d.loc;
  camera_medium_ = gs_.medium_outside; // pbrt-v4: the camera is in the current outside medium
  camera_from_world_ = gs_.ctm;
  bool ok = false;
  Transform wfc = inverse(gs_.ctm, ok);
  if (!ok) fail(d.loc, "Camera: the camera transform is singular");
  coord_systems_["camera"] = wfc;
  if (Param* q = p.one("fov", {"float"})) {
    if (!(q->nums[0] > 0.0 && q->nums[0] < 180.0))
      fail(q->loc, fmt::format("{}: \"float fov\": must be in (0, 180)", p.what()));
    fov_ = q->nums[0];
  }
  for (const char* lens : {"lensradius", "focaldistance"})
    if (p.find(lens))
      warn(p.find(lens)->loc,
           fmt::format("{}: \"{}\": Canopy's camera is a pinhole (no thin lens), ignored", p.what(),
                       lens));
  p.finish();
}

void Reader::finish_camera(const Loc& loc) {
  bool ok = false;
  Transform wfc = inverse(camera_from_world_, ok); // identity without a Camera: pbrt's default
  if (!ok) fail(camera_set_ ? camera_loc_ : loc, "Camera: the camera transform is singular");
  double3 pos = wfc.t;
  double3 fwd = linear(wfc, {0, 0, 1}), up = linear(wfc, {0, 1, 0}), right = linear(wfc, {1, 0, 0});
  if (!(len3(fwd) > 0.0 && len3(up) > 0.0 && len3(right) > 0.0) ||
      !std::isfinite(len3(fwd) + len3(up) + len3(right) + dot3(pos, pos)))
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the camera transform is out of range");
  // Handedness (the format page, "Cameras", and pbrt-v4's PerspectiveCamera): in camera space
  // pbrt looks down +z with +y up, and raster x grows with camera +x. That frame is left-handed:
  // +x = cross(+y, +z). Canopy's camera (host/render/camera.cpp) puts raster x along
  // cross(forward, up), a right-handed frame. So when worldFromCamera keeps orientation
  // (det > 0: a plain LookAt, where camera +x = world cross(up, dir)) pbrt's image is the mirror
  // of what Canopy would show from the same eye, and Canopy must render the mirrored world:
  // every shape and light is reflected through the plane that holds the eye, the view direction
  // and the up vector (world_fix_), which swaps the two sides of the image and nothing else.
  // When worldFromCamera flips orientation (the common "Scale -1 1 1" before LookAt), the frames
  // already agree and the world is kept as written.
  double det = wfc.det();
  if (det > 0.0) {
    double rl = len3(right);
    double3 n = right * (1.0 / rl);
    Transform r; // p - 2 ((p - pos) . n) n
    double nn[3] = {n.x, n.y, n.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.m[i][j] = (i == j ? 1.0 : 0.0) - 2.0 * nn[i] * nn[j];
    r.t = n * (2.0 * dot3(pos, n));
    world_fix_ = r;
  }
  // A camera transform with scale or shear changes pbrt's rays; Canopy's camera is a pinhole
  // with an orthonormal frame: only the eye and the view and up directions are kept.
  double3 cols[3] = {right, up, fwd};
  bool ortho = true;
  for (int i = 0; i < 3; ++i) {
    ortho = ortho && std::fabs(len3(cols[i]) - 1.0) < 1e-6;
    ortho = ortho && std::fabs(dot3(cols[i], cols[(i + 1) % 3])) < 1e-6;
  }
  if (!ortho)
    warn(camera_set_ ? camera_loc_ : loc,
         "Camera: the camera transform scales or shears (only the eye, view and up directions "
         "are kept), the rest ignored");
  if (auto e = check_coordinate(to_float3(pos)); !e.empty())
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the eye " + e);
  scene_.origin = pos;
  Camera& c = scene_.camera;
  c.position = make_float3(0, 0, 0);
  double fl = len3(fwd), ul = len3(up);
  c.look_at = to_float3(fwd * (1.0 / fl));
  c.up = to_float3(up * (1.0 / ul));
  // pbrt's fov spans the shorter image axis (PerspectiveCamera: the screen window is
  // [-1, 1] on the shorter axis); Canopy's fov_y_deg spans the vertical one. On a tall film the
  // horizontal half-width is tan(fov/2), so the vertical one is tan(fov/2) * height / width.
  const double d2r = 3.14159265358979323846 / 180.0;
  double fy = fov_;
  if (scene_.film.height > scene_.film.width)
    fy = 2.0 *
         std::atan(std::tan(0.5 * fov_ * d2r) * double(scene_.film.height) /
                   double(scene_.film.width)) /
         d2r;
  c.fov_y_deg = float(fy);
  if (!(c.fov_y_deg > 0.0f && c.fov_y_deg < 180.0f))
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the vertical field of view is out of range");
}

} // namespace canopy::pbrt
