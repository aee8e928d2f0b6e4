#include "render/camera.h"

#include <cmath>

namespace canopy {

CameraParams make_camera_params(const Camera& cam, int width, int height) {
  float3 forward = normalize(cam.look_at - cam.position);
  float3 right = normalize(cross(forward, cam.up));
  float3 up = cross(right, forward);
  float half_h = std::tan(0.5f * cam.fov_y_deg * float(M_PI) / 180.0f);
  float half_w = half_h * float(width) / float(height);
  CameraParams p{};
  p.origin = f4_from3(cam.position, 0.0f);
  p.lower_left = f4_from3(forward - right * half_w + up * half_h, 0.0f);
  p.du = f4_from3(right * (2.0f * half_w / float(width)), 0.0f);
  p.dv = f4_from3(up * (-2.0f * half_h / float(height)), 0.0f);
  p.width = width;
  p.height = height;
  return p;
}

} // namespace canopy
