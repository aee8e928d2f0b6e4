#include "cl/kernel_args.h"

#include <fmt/format.h>

#include <cstring>

namespace canopy {

const ArgValue* KernelArgs::find(std::string_view name) const {
  auto it = index_.find(name);
  if (it == index_.end() || values_[it->second].empty()) return nullptr;
  return &values_[it->second];
}

const cl::Buffer& KernelArgs::buffer(std::string_view name) const {
  const ArgValue* v = find(name);
  if (!v || !v->is_buffer())
    throw ClError(fmt::format("kernel argument table: {} is not a buffer ({})", name,
                              v ? v->type() : "no value"));
  return v->buffer();
}

size_t KernelArgs::slot(std::string_view name) {
  auto it = index_.find(name);
  if (it != index_.end()) return it->second;
  values_.emplace_back();
  index_.emplace(std::string(name), values_.size() - 1);
  return values_.size() - 1;
}

BoundKernel::BoundKernel(const cl::Program& program, const std::string& name, KernelArgs& args)
    : name_(name), args_(&args) {
  try {
    kernel_ = cl::Kernel(program, name.c_str());
  } catch (const cl::Error& e) {
    throw ClError(describe_cl_error(e, fmt::format("kernel {}", name)));
  }
  cl_uint n = kernel_.getInfo<CL_KERNEL_NUM_ARGS>();
  for (cl_uint i = 0; i < n; ++i) {
    Param p;
    cl_kernel_arg_address_qualifier aq;
    try {
      p.name = kernel_.getArgInfo<CL_KERNEL_ARG_NAME>(i);
      p.type = kernel_.getArgInfo<CL_KERNEL_ARG_TYPE_NAME>(i);
      aq = kernel_.getArgInfo<CL_KERNEL_ARG_ADDRESS_QUALIFIER>(i);
    } catch (const cl::Error& e) {
      throw ClError(describe_cl_error(
          e, fmt::format("kernel {}: argument {} has no name (was the program built with "
                         "-cl-kernel-arg-info?)",
                         name, i)));
    }
    // The info strings may carry their terminating NUL.
    while (!p.name.empty() && p.name.back() == '\0')
      p.name.pop_back();
    while (!p.type.empty() && p.type.back() == '\0')
      p.type.pop_back();
    if (aq == CL_KERNEL_ARG_ADDRESS_LOCAL)
      throw ClError(fmt::format("kernel {}: argument {} is a __local pointer, which kernel "
                                "argument binding does not support",
                                name, p.name));
    p.buffer = aq == CL_KERNEL_ARG_ADDRESS_GLOBAL || aq == CL_KERNEL_ARG_ADDRESS_CONSTANT;
    p.slot = args.slot(p.name);
    params_.push_back(std::move(p));
  }
  chosen_.resize(params_.size());
}

const cl::Kernel& BoundKernel::bind(std::initializer_list<LaunchArg> launch) {
  for (size_t i = 0; i < params_.size(); ++i)
    chosen_[i] = &args_->values_[params_[i].slot];
  for (const LaunchArg& a : launch) {
    size_t i = 0;
    while (i < params_.size() && params_[i].name != a.name)
      ++i;
    if (i == params_.size())
      throw ClError(
          fmt::format("kernel {} has no argument named {} (given for this launch)", name_, a.name));
    chosen_[i] = &a.value;
  }
  for (size_t i = 0; i < params_.size(); ++i) {
    const Param& p = params_[i];
    const ArgValue& v = *chosen_[i];
    if (v.empty())
      throw ClError(fmt::format("kernel {}: argument {} ({}) has no value", name_, p.name, p.type));
    if (p.buffer ? !v.is_buffer() : std::strcmp(v.type(), p.type.c_str()) != 0)
      throw ClError(fmt::format("kernel {}: argument {} is {} but the host gives {}", name_, p.name,
                                p.type, v.type()));
    cl_int err = clSetKernelArg(kernel_(), cl_uint(i), v.size(), v.data());
    if (err != CL_SUCCESS)
      throw ClError(fmt::format("kernel {}: clSetKernelArg of argument {} ({}) failed with {} ({})",
                                name_, p.name, p.type, cl_error_name(err), err));
  }
  return kernel_;
}

} // namespace canopy
