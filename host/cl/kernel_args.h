// Kernel arguments bound by name. Programs are built with -cl-kernel-arg-info (ClRuntime), so each
// kernel reports its parameters' names and types: the kernel's OpenCL C signature is the one
// declaration of its arguments, and their order lives only there.
//
// The host keeps a table name -> value (KernelArgs: buffers and scalars). A BoundKernel reads its
// kernel's parameter list once, maps each parameter to a slot of the table (an index, no string
// lookup per launch), and bind() sets every argument from the table, or from the values given for
// that launch (per-launch names such as "count" are best never put in the table, so a launch that
// forgets one fails instead of reusing a stale value). A parameter without a value, a value of
// another type than the parameter's, or a launch value that names no parameter is a ClError naming
// the kernel and the parameter: the kernel and the host cannot silently disagree.
#pragma once

#include "cl/runtime.h"
#include "compat.h"

#include <cstring>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace canopy {

// One argument's value: a buffer (for a __global or __constant pointer parameter) or a scalar
// tagged with its OpenCL C type name, which must equal the parameter's. Constructors exist for
// the scalar types the kernels take; a default-constructed value, or a null buffer, is "no value".
class ArgValue {
public:
  ArgValue() = default;
  ArgValue(const cl::Buffer& b) : buffer_(b) {
    if (b() != nullptr) type_ = kBuffer, size_ = sizeof(cl_mem), is_buffer_ = true;
  }
  ArgValue(cl_int v) { store("int", v); }
  ArgValue(cl_uint v) { store("uint", v); }
  ArgValue(cl_ulong v) { store("ulong", v); }
  ArgValue(cl_float v) { store("float", v); }
  ArgValue(const float4& v) { store("float4", v); }
  ArgValue(const int2& v) { store("int2", v); }
  ArgValue(const int4& v) { store("int4", v); }

  bool empty() const { return type_ == nullptr; }
  // A flag, not type_ == kBuffer: the literal's address can differ between translation units
  // (AddressSanitizer gives each its own copy), which made buffers look like scalars.
  bool is_buffer() const { return is_buffer_; }
  // "buffer", an OpenCL C scalar type name ("int", "float4", ...), or "no value".
  const char* type() const { return type_ ? type_ : "no value"; }
  // The buffer (a null buffer if this is not one).
  const cl::Buffer& buffer() const { return buffer_; }
  size_t size() const { return size_; }
  // What clSetKernelArg takes: the cl_mem handle for a buffer, the scalar's bytes otherwise.
  const void* data() const { return is_buffer() ? static_cast<const void*>(&buffer_()) : bytes_; }

  static constexpr const char* kBuffer = "buffer";

private:
  template <class T> void store(const char* type, const T& v) {
    static_assert(sizeof(T) <= sizeof(bytes_));
    type_ = type;
    size_ = sizeof(T);
    std::memcpy(bytes_, &v, sizeof(T));
  }

  const char* type_ = nullptr;
  size_t size_ = 0;
  bool is_buffer_ = false;
  alignas(16) unsigned char bytes_[16] = {};
  cl::Buffer buffer_;
};

// A value given to one launch only: bind({{"count", n}, {"queue", q}}).
struct LaunchArg {
  const char* name;
  ArgValue value;
};

// The table of argument values shared by the kernels bound to it.
class KernelArgs {
public:
  // Sets (or replaces) the value of `name` for every kernel bound to this table.
  void set(std::string_view name, const ArgValue& value) { values_[slot(name)] = value; }
  // The value of `name`, or null if it has none.
  const ArgValue* find(std::string_view name) const;
  // The buffer named `name`; throws ClError if there is none.
  const cl::Buffer& buffer(std::string_view name) const;

private:
  friend class BoundKernel;
  size_t slot(std::string_view name); // created without a value on first use
  std::vector<ArgValue> values_;
  std::map<std::string, size_t, std::less<>> index_;
};

// A kernel whose arguments are set by name from a KernelArgs table. The table must outlive it.
class BoundKernel {
public:
  struct Param {
    std::string name;
    std::string type; // OpenCL C type name as the kernel declares it, e.g. "int", "float4*"
    bool buffer;      // a __global or __constant pointer
    size_t slot;      // in the table
  };

  // Throws ClError if the program has no such kernel, was built without -cl-kernel-arg-info, or
  // the kernel takes a kind of argument the binder does not support (__local pointers).
  BoundKernel(const cl::Program& program, const std::string& name, KernelArgs& args);

  // Sets every argument, each from `launch` if named there, else from the table, and returns the
  // kernel, ready to enqueue. Throws ClError naming the kernel and the parameter on a missing
  // value or a type mismatch, and on a launch value that names no parameter.
  const cl::Kernel& bind(std::initializer_list<LaunchArg> launch = {});

  const std::string& name() const { return name_; }
  const std::vector<Param>& params() const { return params_; }
  const cl::Kernel& kernel() const { return kernel_; }

private:
  std::string name_;
  cl::Kernel kernel_;
  KernelArgs* args_;
  std::vector<Param> params_;
  std::vector<const ArgValue*> chosen_; // per parameter, reused by bind()
};

} // namespace canopy
