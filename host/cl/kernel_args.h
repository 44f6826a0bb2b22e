// kernel_args.h: kernel arguments bound by name. Each kernel's argument names, in the order of its
// signature in kernels/*.cl, are listed once here (kernel_args.cpp); the host sets "status_word",
// never "argument 4 + 5". tests/device/kernel_args_test.cpp checks every list against the kernel
// the device built from source (clGetKernelArgInfo) for each build variant, so a signature that
// changes without its list fails there. The lists, not the program, are read at run time: some
// drivers lose argument names in cached binaries.
#pragma once

#include <string>
#include <vector>

#include "cl/cl_runtime.h"

namespace narval {

// The argument names of `kernel` in order. Throws std::logic_error for a kernel with no list.
const std::vector<std::string>& kernelArgumentNames(const std::string& kernel);
// Every kernel with a list.
std::vector<std::string> kernelsWithArgumentNames();

class NamedKernel {
 public:
  NamedKernel() = default;
  NamedKernel(const cl::Program& program, const std::string& name);
  // Sets the argument called `arg`; throws std::logic_error naming the kernel and its arguments
  // when it has none of that name.
  template <typename T>
  void set(const std::string& arg, const T& value) {
    kernel_.setArg(index(arg), value);
  }
  const cl::Kernel& get() const { return kernel_; }

 private:
  cl_uint index(const std::string& arg) const;
  cl::Kernel kernel_;
  std::string name_;
  const std::vector<std::string>* args_ = nullptr;
};

}  // namespace narval
