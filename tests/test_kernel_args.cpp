// Kernel arguments bound by name (host/cl/kernel_args.h) on PoCL: values reach the parameter of
// their name whatever the declaration order, a launch's own values override the table for that
// launch only, and every way the host and a kernel signature can disagree (a missing value, a
// null buffer, a scalar of another type, a buffer for a scalar or the reverse, a launch value that
// names no parameter) is a ClError naming the kernel and the argument.
#include "cl/kernel_args.h"
#include "cl/runtime.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace canopy;

namespace {

// Two float scalars and two buffers of one type: binding them by position in the wrong order
// would still run, and give other numbers.
const char* kSource = R"CL(
__kernel void axpb(__global float* out, float scale_a, int n, __global const float* x,
                   float offset_b, __global const float* y) {
  int i = get_global_id(0);
  if (i >= n) return;
  out[i] = scale_a * x[i] + offset_b + 100.0f * y[i];
}
__kernel void scalars(__global uint* out, uint u, ulong big, float4 v, int2 p) {
  out[0] = u;
  out[1] = (uint)(big >> 32);
  out[2] = (uint)big;
  out[3] = as_uint(v.z);
  out[4] = (uint)p.y;
}
)CL";

class KernelArgsTest : public ::testing::Test {
protected:
  void SetUp() override {
    program_ = rt_.build_program_source(kSource);
    x_ = {1, 2, 3, 4, 5};
    y_ = {0.5f, 0.25f, 0, 1, 2};
    args_.set("x", buffer(x_));
    args_.set("y", buffer(y_));
    args_.set("out", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, 8 * sizeof(float)));
    args_.set("scale_a", 3.0f);
    args_.set("offset_b", -1.0f);
  }
  template <class T> cl::Buffer buffer(std::vector<T>& v) {
    return cl::Buffer(rt_.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                      v.data());
  }
  template <class T> std::vector<T> read(const cl::Buffer& b, size_t n) {
    std::vector<T> v(n);
    rt_.queue().enqueueReadBuffer(b, CL_TRUE, 0, n * sizeof(T), v.data());
    return v;
  }
  // The message of the ClError that bind() throws, or "" if it does not throw.
  std::string bind_error(BoundKernel& k, std::initializer_list<LaunchArg> launch = {}) {
    try {
      k.bind(launch);
    } catch (const ClError& e) {
      return e.what();
    }
    return "";
  }

  ClRuntime rt_;
  cl::Program program_;
  KernelArgs args_;
  std::vector<float> x_, y_;
};

TEST_F(KernelArgsTest, ValuesReachTheParameterOfTheirNameInAnyOrder) {
  BoundKernel k(program_, "axpb", args_);
  ASSERT_EQ(k.params().size(), 6u);
  EXPECT_EQ(k.params()[1].name, "scale_a");
  EXPECT_EQ(k.params()[1].type, "float");
  EXPECT_TRUE(k.params()[3].buffer);
  enqueue_1d(rt_.queue(), k.bind({{"n", 5}}), 5);
  std::vector<float> out = read<float>(args_.buffer("out"), 5);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_EQ(out[i], 3.0f * x_[i] - 1.0f + 100.0f * y_[i]) << i;

  // A launch value overrides the table for that launch only.
  enqueue_1d(rt_.queue(), k.bind({{"n", 5}, {"offset_b", 7.0f}, {"y", args_.buffer("x")}}), 5);
  out = read<float>(args_.buffer("out"), 5);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_EQ(out[i], 3.0f * x_[i] + 7.0f + 100.0f * x_[i]) << i;
  enqueue_1d(rt_.queue(), k.bind({{"n", 5}}), 5);
  out = read<float>(args_.buffer("out"), 5);
  for (size_t i = 0; i < 5; ++i)
    EXPECT_EQ(out[i], 3.0f * x_[i] - 1.0f + 100.0f * y_[i]) << i;
}

TEST_F(KernelArgsTest, EveryScalarTypeArrivesBitExact) {
  KernelArgs args;
  cl::Buffer out(rt_.context(), CL_MEM_READ_WRITE, 5 * sizeof(cl_uint));
  args.set("out", out);
  args.set("p", make_int2(-7, 123456789));
  args.set("v", make_float4(1, 2, 0.1f, 4));
  args.set("big", cl_ulong(0x0123456789abcdefull));
  args.set("u", cl_uint(0xfedcba98u));
  BoundKernel k(program_, "scalars", args);
  enqueue_1d(rt_.queue(), k.bind(), 1);
  std::vector<cl_uint> r = read<cl_uint>(out, 5);
  EXPECT_EQ(r[0], 0xfedcba98u);
  EXPECT_EQ(r[1], 0x01234567u);
  EXPECT_EQ(r[2], 0x89abcdefu);
  EXPECT_EQ(r[3], float_as_uint_(0.1f));
  EXPECT_EQ(r[4], 123456789u);
}

TEST_F(KernelArgsTest, AMissingValueNamesTheKernelAndTheArgument) {
  KernelArgs args; // "offset_b" never set
  args.set("out", args_.buffer("out"));
  args.set("x", args_.buffer("x"));
  args.set("y", args_.buffer("y"));
  args.set("scale_a", 3.0f);
  BoundKernel k(program_, "axpb", args);
  std::string e = bind_error(k, {{"n", 5}});
  EXPECT_NE(e.find("kernel axpb"), std::string::npos) << e;
  EXPECT_NE(e.find("argument offset_b (float) has no value"), std::string::npos) << e;
  // A per-launch value the launch forgets is missing too (it is not in the table).
  e = bind_error(k, {{"offset_b", 1.0f}});
  EXPECT_NE(e.find("kernel axpb: argument n (int) has no value"), std::string::npos) << e;
  // A null buffer is no value.
  args.set("offset_b", 1.0f);
  args.set("x", cl::Buffer());
  e = bind_error(k, {{"n", 5}});
  EXPECT_NE(e.find("kernel axpb: argument x (float*) has no value"), std::string::npos) << e;
  args.set("x", args_.buffer("x"));
  EXPECT_EQ(bind_error(k, {{"n", 5}}), "");
}

TEST_F(KernelArgsTest, ATypeMismatchNamesTheKernelTheArgumentAndBothTypes) {
  BoundKernel k(program_, "axpb", args_);
  std::string e = bind_error(k, {{"n", cl_uint(5)}});
  EXPECT_NE(e.find("kernel axpb: argument n is int but the host gives uint"), std::string::npos)
      << e;
  e = bind_error(k, {{"n", 5}, {"scale_a", args_.buffer("x")}});
  EXPECT_NE(e.find("kernel axpb: argument scale_a is float but the host gives buffer"),
            std::string::npos)
      << e;
  e = bind_error(k, {{"n", 5}, {"x", 1.0f}});
  EXPECT_NE(e.find("kernel axpb: argument x is float* but the host gives float"), std::string::npos)
      << e;
}

TEST_F(KernelArgsTest, ALaunchValueThatNamesNoParameterIsAnError) {
  BoundKernel k(program_, "axpb", args_);
  std::string e = bind_error(k, {{"n", 5}, {"scale", 2.0f}});
  EXPECT_NE(e.find("kernel axpb has no argument named scale"), std::string::npos) << e;
}

TEST_F(KernelArgsTest, AnUnknownKernelIsAnError) {
  try {
    BoundKernel k(program_, "axbp", args_);
    FAIL() << "no error";
  } catch (const ClError& e) {
    EXPECT_NE(std::string(e.what()).find("kernel axbp"), std::string::npos) << e.what();
  }
}

TEST_F(KernelArgsTest, AProgramBuiltWithoutArgumentInfoIsAClearError) {
  cl::Program bare(rt_.context(), kSource);
  bare.build({rt_.device()}, "-cl-std=CL1.2");
  cl::Kernel probe(bare, "axpb");
  cl_int err = clGetKernelArgInfo(probe(), 0, CL_KERNEL_ARG_NAME, 0, nullptr, nullptr);
  // PoCL (the device Canopy targets) reports no names without the option, so the error path
  // below is always exercised; an implementation that reports them anyway fails here instead of
  // skipping the check.
  ASSERT_EQ(err, CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
      << "argument names without -cl-kernel-arg-info: the binder's error path is not reachable";
  try {
    BoundKernel k(bare, "axpb", args_);
    FAIL() << "no error";
  } catch (const ClError& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("kernel axpb"), std::string::npos) << m;
    EXPECT_NE(m.find("-cl-kernel-arg-info"), std::string::npos) << m;
  }
}

} // namespace
