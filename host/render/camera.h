#pragma once

#include "scene/scene.h"
#include "types.h"

namespace canopy {

// Pinhole camera: the image plane at distance 1 spans tan(fov/2) vertically; pixel (x, y) covers
// lower_left + du*[x, x+1) + dv*[y, y+1), with y = 0 the top row.
CameraParams make_camera_params(const Camera& cam, int width, int height);

} // namespace canopy
