// kage._kage_jax: the extension behind kage.jax (python/kage/jax). It registers configs by Spec hash and
// hands JAX the XLA FFI handlers and their state types as capsules; the Python side registers them with
// jax.ffi and calls them with jax.ffi.ffi_call.
#include <pybind11/pybind11.h>

#include <algorithm>
#include <thread>

#include "api/environment.h"
#include "api/jax/ffi_handlers.h"
#include "api/jax/jax_config.h"
#include "api/python/paths.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/visual_state.h"

namespace py = pybind11;

namespace {

py::dict bundle(const kage::jax::HandlerBundle& b) {
  py::dict d;
  d["instantiate"] = py::capsule(reinterpret_cast<void*>(b.instantiate));
  d["execute"] = py::capsule(reinterpret_cast<void*>(b.execute));
  return d;
}

py::dict state_type(const kage::jax::StateType& t) {
  py::dict d;
  d["type_id"] = py::capsule(static_cast<void*>(t.type_id));
  d["type_info"] = py::capsule(const_cast<void*>(static_cast<const void*>(t.type_info)));
  return d;
}

/// Loads and registers a config; its sizes as a dict. RuntimeError with the loader's text on failure.
py::dict register_config(const std::string& path, const std::string& asset_root) {
  kage::jax::RegisterResult r;
  {
    py::gil_scoped_release release;
    r = kage::jax::register_config(path, asset_root);
  }
  if (!r.config) throw std::runtime_error(r.error);
  const kage::jax::JaxConfig& c = *r.config;
  py::dict d;
  d["spec_hash"] = c.spec_hash;
  d["height"] = c.visual.H;
  d["width"] = c.visual.W;
  d["latent_bytes"] = sizeof(kage::LatentState);
  d["visual_bytes"] = sizeof(kage::VisualState);
  d["segment_bytes"] = c.segment_stride;
  return d;
}

/// Why `num_envs` environments of a registered config do not fit: kage::memory_refusal, make_vec's limit for a
/// CPU batch (more than half of the machine's memory), with the CPU handlers' threads (one per core, at most one
/// per environment); empty when they fit.
std::string memory_refusal(const std::string& spec_hash, int64_t num_envs) {
  const std::shared_ptr<const kage::jax::JaxConfig> c = kage::jax::find_config(spec_hash);
  if (!c) throw std::runtime_error("kage.jax: no config with spec hash " + spec_hash + " is registered");
  kage::LoweredConfig config;
  config.latent = c->latent;
  config.visual = c->visual;
  const int64_t threads =
      std::max<int64_t>(1, std::min<int64_t>(num_envs, std::max(1u, std::thread::hardware_concurrency())));
  return kage::memory_refusal(config, num_envs, threads);
}

}  // namespace

PYBIND11_MODULE(_kage_jax, m) {
  m.doc() = "The XLA FFI handlers of kage.jax; use kage.jax instead.";
  kage::python::register_paths(m);
  m.def("register_config", &register_config, py::arg("path"), py::arg("asset_root"),
        "Loads a config for the FFI handlers, keyed by its Spec hash; returns its sizes.");
  m.def("memory_refusal", &memory_refusal, py::arg("spec_hash"), py::arg("num_envs"),
        "Why num_envs environments of a registered config exceed make_vec's memory limit; '' when they fit.");
  m.def("targets", [] {
    // platform -> {target name -> {stage -> capsule}}, as jax.ffi.register_ffi_target takes them.
    py::dict platforms, cpu;
    cpu["kage_reset"] = bundle(kage::jax::cpu_reset_handler());
    cpu["kage_step"] = bundle(kage::jax::cpu_step_handler());
    platforms["cpu"] = cpu;
#if defined(KAGE_JAX_HAVE_CUDA)
    py::dict cuda;
    cuda["kage_reset"] = bundle(kage::jax::cuda_reset_handler());
    cuda["kage_step"] = bundle(kage::jax::cuda_step_handler());
    platforms["CUDA"] = cuda;
#endif
    return platforms;
  }, "platform -> {target -> {stage -> handler capsule}}.");
  m.def("state_types", [] {
    // platform -> (type name, registration), as jax.ffi.register_ffi_type takes them.
    py::dict types;
    types["cpu"] = py::make_tuple("kage_jax_cpu_instance", state_type(kage::jax::cpu_instance_type()));
#if defined(KAGE_JAX_HAVE_CUDA)
    types["CUDA"] = py::make_tuple("kage_jax_cuda_instance", state_type(kage::jax::cuda_instance_type()));
#endif
    return types;
  }, "platform -> (name, {type_id, type_info}) of the handlers' instantiate state.");
}
