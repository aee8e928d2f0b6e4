// The intersect_closest kernel bound to a ray batch (queue = every ray, in order), shared by the
// Embree comparison test and the intersect benchmark.
#pragma once

#include "accel/bvh.h"
#include "cl/runtime.h"
#include "render/device_scene.h"
#include "support/procedural_mesh.h"

#include <numeric>

namespace canopy::testing {

class ClosestHitKernel {
public:
  ClosestHitKernel(ClRuntime& rt, const cl::Program& program, const Bvh& bvh,
                   const std::vector<Primitive>& prims, const Rays& rays)
      : rt_(rt), count_(rays.o.size()), kernel_(program, "intersect_closest") {
    std::vector<int> queue(count_);
    std::iota(queue.begin(), queue.end(), 0);
    const cl::Context& ctx = rt.context();
    buffers_ = {upload_buffer(ctx, bvh.nodes),
                upload_buffer(ctx, bvh.prim_index),
                upload_buffer(ctx, prims),
                upload_buffer(ctx, queue),
                upload_buffer(ctx, rays.o),
                upload_buffer(ctx, rays.d),
                cl::Buffer(ctx, CL_MEM_READ_WRITE, count_ * sizeof(Hit))};
    for (int i = 0; i < 3; ++i)
      kernel_.setArg(i, buffers_[size_t(i)]);
    kernel_.setArg(3, buffers_[3]);
    kernel_.setArg(4, cl_int(count_));
    for (int i = 4; i < 7; ++i)
      kernel_.setArg(i + 1, buffers_[size_t(i)]);
  }

  // Runs the kernel over every ray and waits for it.
  void run(size_t local = kDefaultLocalSize) {
    enqueue_1d(rt_.queue(), kernel_, count_, local);
    rt_.queue().finish();
  }

  std::vector<Hit> hits() {
    std::vector<Hit> h(count_);
    rt_.queue().enqueueReadBuffer(buffers_[6], CL_TRUE, 0, count_ * sizeof(Hit), h.data());
    return h;
  }

private:
  ClRuntime& rt_;
  size_t count_;
  cl::Kernel kernel_;
  std::vector<cl::Buffer> buffers_;
};

} // namespace canopy::testing
