// What the intersect kernels' test and benchmark harnesses share: a kernel bound by name to the
// scene's geometry (BVH nodes, leaf blocks, primitives) and a batch of `count` rays, run over the
// whole batch. ClosestHitKernel and ShadowKernel add their ray buffers, then call bind().
#pragma once

#include "accel/bvh.h"
#include "cl/kernel_args.h"
#include "cl/runtime.h"
#include "render/device_scene.h"

#include <string>
#include <vector>

namespace canopy::testing {

class GeometryKernel {
public:
  GeometryKernel(ClRuntime& rt, const cl::Program& program, const std::string& name, const Bvh& bvh,
                 const std::vector<Primitive>& prims, size_t count)
      : rt_(rt), count_(count), kernel_(program, name, args_) {
    const cl::Context& ctx = rt.context();
    args_.set("nodes", upload_buffer(ctx, bvh.nodes));
    args_.set("leaf_blocks", upload_buffer(ctx, bvh.leaf_blocks));
    args_.set("prims", upload_buffer(ctx, prims));
    args_.set("count", cl_int(count_));
  }
  GeometryKernel(const GeometryKernel&) = delete; // kernel_ points into args_
  GeometryKernel& operator=(const GeometryKernel&) = delete;

  // Runs the kernel over every ray and waits for it.
  void run(size_t local = kDefaultLocalSize) {
    enqueue_1d(rt_.queue(), kernel_.kernel(), count_, local);
    rt_.queue().finish();
  }

protected:
  ClRuntime& rt_;
  size_t count_;
  KernelArgs args_;
  BoundKernel kernel_;
};

} // namespace canopy::testing
