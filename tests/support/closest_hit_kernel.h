// The intersect_closest kernel bound to a ray batch (queue = every ray, in order), shared by the
// Embree comparison test and the intersect benchmark.
#pragma once

#include "support/geometry_kernel.h"
#include "support/procedural_mesh.h"

#include <numeric>

namespace canopy::testing {

class ClosestHitKernel : public GeometryKernel {
public:
  ClosestHitKernel(ClRuntime& rt, const cl::Program& program, const Bvh& bvh,
                   const std::vector<Primitive>& prims, const Rays& rays)
      : GeometryKernel(rt, program, "intersect_closest", bvh, prims, rays.o.size()) {
    std::vector<int> queue(count_);
    std::iota(queue.begin(), queue.end(), 0);
    const cl::Context& ctx = rt.context();
    args_.set("queue", upload_buffer(ctx, queue));
    args_.set("ray_o", upload_buffer(ctx, rays.o));
    args_.set("ray_d", upload_buffer(ctx, rays.d));
    args_.set("hits", cl::Buffer(ctx, CL_MEM_READ_WRITE, count_ * sizeof(Hit)));
    kernel_.bind();
  }

  std::vector<Hit> hits() {
    std::vector<Hit> h(count_);
    rt_.queue().enqueueReadBuffer(args_.buffer("hits"), CL_TRUE, 0, count_ * sizeof(Hit), h.data());
    return h;
  }
};

} // namespace canopy::testing
