// kernel_sources.h: the OpenCL sources embedded at build time (tools/embed_kernels.cpp), already
// flattened with #line markers. Key: the kernel file name, e.g. "pathtrace.cl".
#pragma once

#include <map>
#include <string>

namespace narval {
const std::map<std::string, std::string>& kernelSources();
}
