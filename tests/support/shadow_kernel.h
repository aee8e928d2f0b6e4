// The intersect_shadow kernel bound to a batch of shadow segments (Rays with o.w = the segment's
// length), shared by the Embree comparison test and the intersect benchmark.
#pragma once

#include "support/geometry_kernel.h"
#include "support/procedural_mesh.h"

namespace canopy::testing {

// run() keeps its answer across runs: the kernel zeroes the contribution of occluded segments,
// so later runs do the same work and give the same answer.
class ShadowKernel : public GeometryKernel {
public:
  ShadowKernel(ClRuntime& rt, const cl::Program& program, const Bvh& bvh,
               const std::vector<Primitive>& prims, const Rays& rays)
      : GeometryKernel(rt, program, "intersect_shadow", bvh, prims, rays.o.size()) {
    std::vector<ShadowItem> items(count_);
    for (size_t i = 0; i < count_; ++i) {
      items[i].origin = rays.o[i];
      items[i].dir = rays.d[i];
      items[i].dir.w = uint_as_float_(uint(i));
      items[i].contribution = make_float4(1, 1, 1, 0);
    }
    args_.set("shadow_items", upload_buffer(rt.context(), items));
    kernel_.bind();
  }

  // 1 where the segment is occluded.
  std::vector<int> occluded() {
    std::vector<ShadowItem> out(count_);
    rt_.queue().enqueueReadBuffer(args_.buffer("shadow_items"), CL_TRUE, 0,
                                  count_ * sizeof(ShadowItem), out.data());
    std::vector<int> r(count_);
    for (size_t i = 0; i < count_; ++i)
      r[i] = out[i].contribution.x == 0.0f;
    return r;
  }
};

} // namespace canopy::testing
