// The path sampler on the device (PoCL) against the host (cl/sampler.h compiled as C++): a test
// kernel draws, for a set of (seed, film pixel, sample index, dimension), the Sobol word of both
// components of the group, the 1D and 2D floats, the counter-stream seed word and a new path's
// state and jitter; every value must be bit-identical to the host's, so the host's statistical
// tests (test_sampler.cpp) cover the device.
#include "cl/runtime.h"
#include "sampler.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

using namespace canopy;

namespace {

const char* kSamplerKernel = R"CL(
#include "sampler.h"
// in[i] = (seed, pixel, sample, dim); words[i] = (word 0, word 1, hash word, state.x);
// floats[i] = (1D, 2D.x, 2D.y, jitter.x), jit_y[i] = jitter.y; states[i]: a new path's state.
__kernel void draw(__global const uint4* in, int count, uint path_sampler, __global uint4* words,
                   __global float4* floats, __global float* jit_y, __global uint4* states) {
  int i = get_global_id(0);
  if (i >= count) return;
  uint4 q = in[i];
  uint key = sampler_pixel_key(q.x, q.y);
  float2 u = sampler_sobol_2d(key, q.z, q.w);
  float2 j;
  uint4 s = path_sampler_start(path_sampler, q.x, q.y, q.z, &j);
  words[i] = (uint4)(sampler_sobol_word(key, q.z, q.w, 0), sampler_sobol_word(key, q.z, q.w, 1),
                     sampler_hash_word(key, q.z, q.w), s.x);
  floats[i] = (float4)(sampler_sobol_1d(key, q.z, q.w), u.x, u.y, j.x);
  jit_y[i] = j.y;
  states[i] = s;
}
)CL";

} // namespace

TEST(KernelSampler, DeviceDrawsTheHostsNumbers) {
  ClRuntime rt;
  cl::Program program = rt.build_program_source(kSamplerKernel);
  std::mt19937 rng(17);
  const int n = 20000;
  std::vector<uint4> in(n);
  for (int i = 0; i < n; ++i) {
    // Small and large sample indices and dimensions, and the first vertices' dimensions.
    uint32_t sample = i % 4 == 0 ? uint32_t(rng()) : uint32_t(rng() % 1024);
    uint32_t dim = i % 5 == 0 ? uint32_t(rng()) : uint32_t(rng() % 80);
    in[size_t(i)] = make_uint4(uint32_t(rng() % 8), uint32_t(rng() % (1 << 20)), sample, dim);
  }
  for (uint32_t kind : {PATH_SAMPLER_INDEPENDENT, PATH_SAMPLER_SOBOL}) {
    SCOPED_TRACE(::testing::Message() << "path sampler " << kind);
    const cl::Context& ctx = rt.context();
    cl::Buffer bin(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(uint4) * n, in.data());
    cl::Buffer bw(ctx, CL_MEM_WRITE_ONLY, sizeof(uint4) * n);
    cl::Buffer bf(ctx, CL_MEM_WRITE_ONLY, sizeof(float4) * n);
    cl::Buffer bj(ctx, CL_MEM_WRITE_ONLY, sizeof(float) * n);
    cl::Buffer bs(ctx, CL_MEM_WRITE_ONLY, sizeof(uint4) * n);
    cl::Kernel k(program, "draw");
    k.setArg(0, bin);
    k.setArg(1, cl_int(n));
    k.setArg(2, cl_uint(kind));
    k.setArg(3, bw);
    k.setArg(4, bf);
    k.setArg(5, bj);
    k.setArg(6, bs);
    rt.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(size_t(n)));
    std::vector<uint4> words(n), states(n);
    std::vector<float4> floats(n);
    std::vector<float> jy(n);
    rt.queue().enqueueReadBuffer(bw, CL_TRUE, 0, sizeof(uint4) * n, words.data());
    rt.queue().enqueueReadBuffer(bf, CL_TRUE, 0, sizeof(float4) * n, floats.data());
    rt.queue().enqueueReadBuffer(bj, CL_TRUE, 0, sizeof(float) * n, jy.data());
    rt.queue().enqueueReadBuffer(bs, CL_TRUE, 0, sizeof(uint4) * n, states.data());
    int mismatches = 0;
    for (int i = 0; i < n && mismatches < 10; ++i) {
      const uint4 q = in[size_t(i)];
      const uint32_t key = sampler_pixel_key(q.x, q.y);
      const float2 u = sampler_sobol_2d(key, q.z, q.w);
      float2 j;
      const uint4 s = path_sampler_start(kind, q.x, q.y, q.z, &j);
      const uint4 w =
          make_uint4(sampler_sobol_word(key, q.z, q.w, 0), sampler_sobol_word(key, q.z, q.w, 1),
                     sampler_hash_word(key, q.z, q.w), s.x);
      const float4 f = make_float4(sampler_sobol_1d(key, q.z, q.w), u.x, u.y, j.x);
      const float4& d = floats[size_t(i)];
      bool same = words[size_t(i)] == w && states[size_t(i)] == s && d.x == f.x && d.y == f.y &&
                  d.z == f.z && d.w == f.w && jy[size_t(i)] == j.y;
      if (!same) {
        ++mismatches;
        ADD_FAILURE() << "draw " << i << " (seed " << q.x << ", pixel " << q.y << ", sample " << q.z
                      << ", dim " << q.w << "): device words " << words[size_t(i)].x << " "
                      << words[size_t(i)].y << ", host " << w.x << " " << w.y;
      }
    }
    EXPECT_EQ(mismatches, 0);
  }
}
