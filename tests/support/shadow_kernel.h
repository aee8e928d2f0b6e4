// The intersect_shadow kernel bound to a batch of shadow segments (Rays with o.w = the segment's
// length), shared by the Embree comparison test and the intersect benchmark.
#pragma once

#include "accel/bvh.h"
#include "cl/kernel_args.h"
#include "cl/runtime.h"
#include "render/device_scene.h"
#include "support/procedural_mesh.h"

namespace canopy::testing {

class ShadowKernel {
public:
  ShadowKernel(ClRuntime& rt, const cl::Program& program, const Bvh& bvh,
               const std::vector<Primitive>& prims, const Rays& rays)
      : rt_(rt), count_(rays.o.size()), kernel_(program, "intersect_shadow", args_) {
    items_.resize(count_);
    for (size_t i = 0; i < count_; ++i) {
      items_[i].origin = rays.o[i];
      items_[i].dir = rays.d[i];
      items_[i].dir.w = uint_as_float_(uint(i));
      items_[i].contribution = make_float4(1, 1, 1, 0);
    }
    const cl::Context& ctx = rt.context();
    args_.set("nodes", upload_buffer(ctx, bvh.nodes));
    args_.set("leaf_blocks", upload_buffer(ctx, bvh.leaf_blocks));
    args_.set("prims", upload_buffer(ctx, prims));
    args_.set("shadow_items", upload_buffer(ctx, items_));
    args_.set("count", cl_int(count_));
    kernel_.bind();
  }
  ShadowKernel(const ShadowKernel&) = delete; // kernel_ points into args_
  ShadowKernel& operator=(const ShadowKernel&) = delete;

  // Runs the kernel over every segment and waits for it. The kernel zeroes the contribution of
  // occluded segments, so later runs do the same work and give the same answer.
  void run(size_t local = kDefaultLocalSize) {
    enqueue_1d(rt_.queue(), kernel_.kernel(), count_, local);
    rt_.queue().finish();
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

private:
  ClRuntime& rt_;
  size_t count_;
  std::vector<ShadowItem> items_;
  KernelArgs args_;
  BoundKernel kernel_;
};

} // namespace canopy::testing
