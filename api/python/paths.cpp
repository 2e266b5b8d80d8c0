#include "api/python/paths.h"

#include <pybind11/stl.h>

#include "compiler/codegen/build.h"
#include "runtime/cuda/nvrtc_search.h"

namespace kage::python {

void register_paths(pybind11::module_& m) {
  m.def("set_runtime_include_dir", &kage::set_runtime_include_dir, pybind11::arg("dir"),
        "The folder holding runtime/ whose headers NVRTC compiles kernels against ($KAGE_ROOT wins).");
  m.def("set_nvrtc_dirs", &kage::set_nvrtc_dirs, pybind11::arg("dirs"),
        "Folders searched first for NVRTC's library (before $CUDA_HOME, the loader's path and /usr/local/cuda).");
  m.def("nvrtc_candidates", &kage::nvrtc_candidates, "What the GPU backend tries to load NVRTC from, in order.");
}

}  // namespace kage::python
