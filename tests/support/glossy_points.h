// Shared by the host tests of BRDF-oriented sampling: a gold-like conductor and a blue plastic of
// a given roughness (alpha = roughness^2), and host copies of the wavefront's path state.
#pragma once

#include "integrator/path_state.h"
#include "support/materials.h"
#include "types.h"

#include <vector>

namespace canopy::test {

inline Material gold_conductor(float roughness) {
  return make_conductor(make_float3(0.18f, 0.42f, 1.37f), make_float3(3.42f, 2.35f, 1.77f),
                        roughness * roughness);
}
inline Material blue_plastic(float roughness) {
  return make_plastic(make_float3(0.3f, 0.4f, 0.5f), make_float3(1, 1, 1), 1.5f,
                      roughness * roughness);
}

// Host copies of the path state (every buffer of PATH_STATE_BUFFERS).
struct HostPaths {
#define CANOPY_PATH_VECTOR(T, name) std::vector<T> name;
  PATH_STATE_BUFFERS(CANOPY_PATH_VECTOR)
#undef CANOPY_PATH_VECTOR
  PathBuffers host() {
    PathBuffers pb;
#define CANOPY_PATH_POINTER(T, name) pb.name = name.data();
    PATH_STATE_BUFFERS(CANOPY_PATH_POINTER)
#undef CANOPY_PATH_POINTER
    return pb;
  }
};

} // namespace canopy::test
