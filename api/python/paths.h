// Where the extension finds the runtime headers (for NVRTC) and NVRTC's library: the Python package
// names them (kage/resources.py), since the extension lives in site-packages, not beside them.
#pragma once

#include <pybind11/pybind11.h>

namespace kage::python {

/// Adds set_runtime_include_dir, set_nvrtc_dirs and nvrtc_candidates to the module.
void register_paths(pybind11::module_& m);

}  // namespace kage::python
