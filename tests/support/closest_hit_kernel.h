// The intersect_closest kernel bound to a ray batch (queue = every ray, in order), shared by the
// Embree comparison test and the intersect benchmark.
#pragma once

#include "accel/bvh.h"
#include "cl/kernel_args.h"
#include "cl/runtime.h"
#include "render/device_scene.h"
#include "support/procedural_mesh.h"

#include <numeric>

namespace canopy::testing {

class ClosestHitKernel {
public:
  ClosestHitKernel(ClRuntime& rt, const cl::Program& program, const Bvh& bvh,
                   const std::vector<Primitive>& prims, const Rays& rays)
      : rt_(rt), count_(rays.o.size()), kernel_(program, "intersect_closest", args_) {
    std::vector<int> queue(count_);
    std::iota(queue.begin(), queue.end(), 0);
    const cl::Context& ctx = rt.context();
    args_.set("nodes", upload_buffer(ctx, bvh.nodes));
    args_.set("leaf_blocks", upload_buffer(ctx, bvh.leaf_blocks));
    args_.set("prims", upload_buffer(ctx, prims));
    args_.set("queue", upload_buffer(ctx, queue));
    args_.set("count", cl_int(count_));
    args_.set("ray_o", upload_buffer(ctx, rays.o));
    args_.set("ray_d", upload_buffer(ctx, rays.d));
    args_.set("hits", cl::Buffer(ctx, CL_MEM_READ_WRITE, count_ * sizeof(Hit)));
    kernel_.bind();
  }
  ClosestHitKernel(const ClosestHitKernel&) = delete; // kernel_ points into args_
  ClosestHitKernel& operator=(const ClosestHitKernel&) = delete;

  // Runs the kernel over every ray and waits for it.
  void run(size_t local = kDefaultLocalSize) {
    enqueue_1d(rt_.queue(), kernel_.kernel(), count_, local);
    rt_.queue().finish();
  }

  std::vector<Hit> hits() {
    std::vector<Hit> h(count_);
    rt_.queue().enqueueReadBuffer(args_.buffer("hits"), CL_TRUE, 0, count_ * sizeof(Hit), h.data());
    return h;
  }

private:
  ClRuntime& rt_;
  size_t count_;
  KernelArgs args_;
  BoundKernel kernel_;
};

} // namespace canopy::testing
