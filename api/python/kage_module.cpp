// kage._kage: the Python binding of include/kage/kage.h (pybind11). It opens batches, steps them with
// actions from numpy arrays, DLPack capsules or raw device pointers, and exports every output without
// a copy: host outputs as numpy arrays, device outputs as DeviceArray (DLPack and
// __cuda_array_interface__). The Python package (python/kage/) builds the Gymnasium-style API on it.
//
// Lifetime: an exported array holds a reference to its batch, so the memory stays allocated while any
// array, tensor or capsule views it, even after close(); its contents change with the next reset/step.
#include <dlpack/dlpack.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <algorithm>
#include <mutex>
#include <string>
#include <vector>

#include "api/python/cuda_streams.h"
#include "api/python/device_array.h"
#include "api/python/front_end.h"
#include "api/python/paths.h"
#include "api/python/step_rows.h"
#include "kage/kage.h"

namespace py = pybind11;

namespace {

/// Raised by open(): a Python exception class and the kind it stands for (set up in the module init).
struct ErrorClasses {
  py::object config, file, device, usage, other;
};
ErrorClasses& error_classes() {
  static ErrorClasses e;
  return e;
}

void raise_value_error(const std::string& message) { throw py::value_error(message); }

/// What a call on a closed batch raises.
constexpr const char* kClosed = "this environment is closed: make a new one with kage.make_vec";

/// Text from the runtime or the front end as a Python str. A config need not be UTF-8, and its lines are
/// quoted in diagnostics: undecodable bytes become U+FFFD instead of a UnicodeDecodeError that would hide
/// the located message.
py::str text(const std::string& s) {
  PyObject* decoded = PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), "replace");
  if (!decoded) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(decoded);
}

using kage::python::DeviceArray;
using kage::python::facts;
using kage::python::numpy_dtype;
using kage::python::shape_text;

/// A batch as Python sees it: kage::Env plus the export of its outputs.
///
/// Threads: every call runs with the GIL released and the batch's lock held, so calls from several threads
/// run one at a time, each one whole, and close() waits for a call in progress; calls after close() raise.
/// The lock is taken only with the GIL released and the GIL is taken back only after the lock is let go,
/// so a thread waiting for one never holds the other.
class PyEnv {
 public:
  explicit PyEnv(std::shared_ptr<kage::Env> env) : env_(std::move(env)), mutex_(std::make_shared<std::mutex>()) {}

  /// The output `name` ("obs", "reward", "terminated", "truncated", "final_mask", "final_obs", or
  /// "info/<field>", "final_info/<field>") as a numpy array (CPU) or a DeviceArray (GPU).
  py::object output(const std::string& name) const {
    std::shared_ptr<kage::Env> owner;
    const Located l = locked([&](kage::Env& e) {
      owner = env_;
      return locate(e, name);
    });
    return export_array(owner, l.data, l.shape, l.dtype);
  }

  /// The runtime's own pointer to output `name` (host or device address), for checks of zero copy.
  uintptr_t data_ptr(const std::string& name) const {
    return locked([&](kage::Env& e) { return reinterpret_cast<uintptr_t>(locate(e, name).data); });
  }

  /// `seeds`: num_envs uint64 values; `mask`: None or num_envs bools (or uint8 0/1). Any strides, byte order
  /// or alignment: each is copied into a native contiguous array first; other dtypes are refused, not cast.
  void reset(const py::array& seeds, const py::object& mask) {
    const int32_t n = num_envs();
    check_dtype(seeds, "seeds", seeds.dtype().kind() == 'u' && seeds.dtype().itemsize() == 8, "uint64");
    const auto native_seeds = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(seeds);
    check_length(native_seeds.size(), n, "seeds");
    std::vector<uint8_t> m;
    if (!mask.is_none()) {
      const py::array given = py::array::ensure(mask);
      if (!given) raise_value_error("mask: a numpy array of booleans");
      const py::dtype dt = given.dtype();
      check_dtype(given, "mask", dt.kind() == 'b' || (dt.kind() == 'u' && dt.itemsize() == 1), "bool or uint8");
      const auto a = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(given);
      check_length(a.size(), n, "mask");
      m.assign(a.data(), a.data() + a.size());
    }
    const uint64_t* s = native_seeds.data();
    raise_if_failed(locked([&](kage::Env& e) {
      Outcome o;
      o.ok = e.reset(s, m.empty() ? nullptr : m.data(), &o.error);
      o.kind = e.last_error_kind();
      return o;
    }));
  }

  /// Host actions: num_envs int32 or int64 values in native byte order, aligned, any stride that is a
  /// multiple of the item size (kage.actions copies other layouts first); other layouts are refused by name.
  void step_host(const py::array& actions) {
    const auto& dt = actions.dtype();
    if ((dt.kind() != 'i') || (dt.itemsize() != 4 && dt.itemsize() != 8) || actions.ndim() != 1)
      raise_value_error("internal: step_host wants a 1-D int32 or int64 array");
    check_length(actions.size(), num_envs(), "actions");
    const py::ssize_t size = dt.itemsize(), stride = actions.strides(0);
    const std::string fix = ": pass np.ascontiguousarray(actions, dtype=np.int64)";
    if (stride % size != 0)
      raise_value_error("actions: a byte stride " + std::to_string(stride) + " is not a multiple of the item size " +
                        std::to_string(size) + " (a field of a packed structured array?)" + fix);
    if (reinterpret_cast<uintptr_t>(actions.data()) % static_cast<uintptr_t>(size) != 0)
      raise_value_error("actions: the data is not aligned to the item size " + std::to_string(size) + fix);
    if (!dt.attr("isnative").cast<bool>())
      raise_value_error("actions: int" + std::to_string(8 * size) + " in the other byte order than this machine's" +
                        fix);
    run_step(kage::Actions{actions.data(), kage::Memory::kHost,
                           dt.itemsize() == 8 ? kage::DType::kInt64 : kage::DType::kInt32,
                           actions.strides(0) / dt.itemsize()});
  }

  /// Device actions at `ptr` (int32 or int64, `stride` elements apart), produced on `producer_stream`
  /// (a __cuda_array_interface__ stream number; -1: no ordering needed).
  void step_device(uintptr_t ptr, bool is_int64, int64_t stride, int64_t producer_stream) {
    if (device() != "cuda")
      raise_value_error("actions are in GPU memory but the environment runs on the CPU: pass host actions "
                        "(e.g. actions.cpu()) or make the environment with device='cuda'");
    if (ptr % (is_int64 ? 8 : 4) != 0)
      raise_value_error("actions: device data at " + std::to_string(ptr) + " is not aligned to the item size: pass "
                        "a contiguous copy (e.g. actions.contiguous())");
    const kage::Actions a{reinterpret_cast<const void*>(ptr), kage::Memory::kDevice,
                          is_int64 ? kage::DType::kInt64 : kage::DType::kInt32, stride};
    raise_if_failed(locked([&](kage::Env& e) {
      Outcome o;
      if (producer_stream != -1 &&
          !kage::python::order_after(kage::python::protocol_stream(producer_stream), e.stream(), &o.error))
        throw std::runtime_error(o.error);
      return step_locked(e, a);
    }));
  }

  /// Device actions from a DLPack capsule (already ordered for this batch's stream by the producer's
  /// __dlpack__(stream=...)). Shape [num_envs], int32 or int64, on CUDA device 0.
  void step_dlpack(py::capsule capsule) {
    auto* t = static_cast<DLManagedTensor*>(PyCapsule_GetPointer(capsule.ptr(), "dltensor"));
    if (!t) throw py::error_already_set();
    const DLTensor& d = t->dl_tensor;
    const int32_t n = num_envs();
    std::string problem;
    if (d.device.device_type != kDLCUDA)
      problem = "a DLPack array on device type " + std::to_string(d.device.device_type);
    else if (d.device.device_id != 0)
      problem = "actions on cuda:" + std::to_string(d.device.device_id) + ", the environment runs on cuda:0";
    else if (d.ndim != 1 || d.shape[0] != n)
      problem = "actions of shape " + shape_text(d) + ", expected (" + std::to_string(n) + ",)";
    else if (d.dtype.lanes != 1 || d.dtype.code != kDLInt || (d.dtype.bits != 32 && d.dtype.bits != 64))
      problem = "actions of DLPack type (code " + std::to_string(d.dtype.code) + ", " + std::to_string(d.dtype.bits) +
                " bits), expected int32 or int64";
    else if ((reinterpret_cast<uintptr_t>(d.data) + d.byte_offset) % (d.dtype.bits / 8) != 0)
      problem = "actions: device data not aligned to the item size: pass a contiguous copy (e.g. actions.contiguous())";
    const kage::Actions a{static_cast<const char*>(d.data) + d.byte_offset, kage::Memory::kDevice,
                          d.dtype.bits == 64 ? kage::DType::kInt64 : kage::DType::kInt32,
                          d.strides ? d.strides[0] : 1};
    // The consumer owns the tensor now: free it after the launch (the caller keeps the array alive).
    PyCapsule_SetName(capsule.ptr(), "used_dltensor");
    if (problem.empty()) {
      try {
        run_step(a);
      } catch (...) {
        if (t->deleter) t->deleter(t);
        throw;
      }
    }
    if (t->deleter) t->deleter(t);
    if (!problem.empty()) raise_value_error(problem);
  }

  /// kage::python::step_rows over these batches: host rows each by its batch's own step, device rows by
  /// kage::step_together with every batch's lock held; a failure names its batch.
  static void step_rows(const std::vector<PyEnv*>& envs, const py::object& actions) {
    auto together = [&envs](const kage::Actions& first_row, int64_t row_stride) {
      Outcome o;
      {
        py::gil_scoped_release release;
        // Every batch's lock, taken in one order by every caller (the address of the lock), so two calls
        // on other threads never deadlock; a batch listed twice is refused by kage.step_batches first.
        std::vector<std::mutex*> mutexes;
        for (PyEnv* env : envs) mutexes.push_back(env->mutex_.get());
        std::sort(mutexes.begin(), mutexes.end());
        std::vector<std::unique_lock<std::mutex>> held;
        for (std::mutex* m : mutexes) held.emplace_back(*m);
        std::vector<kage::Env*> batches;
        for (PyEnv* env : envs) {
          if (!env->env_) throw std::runtime_error(kClosed);
          batches.push_back(env->env_.get());
        }
        int64_t failed = -1;
        o.ok = kage::step_together(batches, first_row, row_stride, &o.error, &failed);
        if (!o.ok && failed >= 0) {
          o.kind = batches[static_cast<size_t>(failed)]->last_error_kind();
          o.error = kage::python::together_failure(static_cast<size_t>(failed), batches.size(), o.error);
        }
      }
      raise_if_failed(o);
    };
    std::vector<kage::python::RowBatch> batches;
    for (PyEnv* env : envs) {
      auto step = [env, rows = envs.size()](size_t row, const kage::Actions& a) {
        Outcome o = env->locked([&](kage::Env& e) { return step_locked(e, a); });
        if (!o.ok) o.error = kage::python::row_failure(row, rows, o.error);
        raise_if_failed(o);
      };
      batches.push_back(env->locked([&](kage::Env& e) {  // one lock a batch: this runs every step
        return kage::python::RowBatch{e.num_envs(), e.backend() == kage::Backend::kGpu, step};
      }));
    }
    kage::python::step_rows(batches, actions, together);
  }

  py::bytes save_state() const {
    std::vector<uint8_t> out;
    locked([&](kage::Env& e) {
      std::string error;
      if (!e.save_state(&out, &error)) throw std::runtime_error(error);
      return 0;
    });
    return py::bytes(reinterpret_cast<const char*>(out.data()), out.size());
  }

  /// `data`: a contiguous buffer of bytes (bytes, bytearray, memoryview, uint8 array; read-only is fine).
  void load_state(const py::buffer& data) {
    const py::buffer_info b = data.request();
    if (b.itemsize != 1 || b.ndim != 1 || b.strides[0] != 1)
      raise_value_error("load_state: a contiguous buffer of bytes (bytes, bytearray, memoryview), got item size " +
                        std::to_string(b.itemsize) + ", " + std::to_string(b.ndim) + " dimensions" +
                        (b.ndim == 1 ? ", byte stride " + std::to_string(b.strides[0]) : std::string()));
    const auto* bytes = static_cast<const uint8_t*>(b.ptr);
    const size_t size = static_cast<size_t>(b.size);
    const std::string error = locked([&](kage::Env& e) {
      std::string error;
      return e.load_state(bytes, size, &error) ? std::string() : error;
    });
    if (!error.empty()) raise_value_error(error);
  }

  void synchronize() {
    raise_if_failed(locked([&](kage::Env& e) {
      Outcome o;
      o.ok = e.synchronize(&o.error);
      o.kind = e.last_error_kind();
      return o;
    }));
  }
  std::string pending_error() {
    return locked([](kage::Env& e) { return e.pending_error(); });
  }

  int32_t num_envs() const {
    return locked([](kage::Env& e) { return e.num_envs(); });
  }
  int32_t height() const {
    return locked([](kage::Env& e) { return e.height(); });
  }
  int32_t width() const {
    return locked([](kage::Env& e) { return e.width(); });
  }
  std::string spec_hash() const {
    return locked([](kage::Env& e) { return e.spec_hash(); });
  }
  std::string device() const {
    return locked([](kage::Env& e) { return std::string(e.backend() == kage::Backend::kGpu ? "cuda" : "cpu"); });
  }
  uintptr_t stream() const {
    return locked([](kage::Env& e) { return reinterpret_cast<uintptr_t>(e.stream()); });
  }
  void set_stream(uintptr_t s) {
    locked([&](kage::Env& e) {
      e.set_stream(reinterpret_cast<void*>(s));
      return 0;
    });
  }

  /// Drops this handle's reference to the batch, after any call in progress on another thread; the
  /// batch is freed now unless exported arrays still view it. Closing twice is harmless.
  void close() {
    py::gil_scoped_release release;
    std::shared_ptr<kage::Env> dropped;
    {
      std::lock_guard<std::mutex> lock(*mutex_);
      dropped = std::move(env_);
    }
    dropped.reset();  // without the GIL: a GPU batch waits for its queued work here
  }
  bool closed() const {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(*mutex_);
    return env_ == nullptr;
  }

 private:
  struct Located {
    const void* data;
    std::vector<int64_t> shape;
    kage::DType dtype;
  };

  /// What a reset, step or synchronize returned, read under the lock.
  struct Outcome {
    bool ok = true;
    std::string error;
    kage::ErrorKind kind = kage::ErrorKind::kNone;
  };

  /// f(env) with the GIL released and the batch's lock held; raises if the batch is closed.
  template <class F>
  std::invoke_result_t<F, kage::Env&> locked(F&& f) const {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(*mutex_);
    if (!env_) throw std::runtime_error(kClosed);
    return f(*env_);
  }

  static Located locate(kage::Env& env, const std::string& name) {
    const int64_t n = env.num_envs();
    Located l{nullptr, {n}, kage::DType::kUInt8};
    if (name == "obs" || name == "final_obs") {
      l.shape = {n, env.height(), env.width(), 3};
      l.data = name == "obs" ? env.obs() : env.final_obs();
    } else if (name == "reward") {
      l.data = env.reward();
      l.dtype = kage::DType::kFloat32;
    } else if (name == "terminated" || name == "truncated" || name == "final_mask") {
      // Bool, as Gymnasium's flags and masks are: a uint8 0/1 mask would index rows 0 and 1 instead of masking.
      l.dtype = kage::DType::kBool;
      l.data = name == "terminated" ? env.terminated() : name == "truncated" ? env.truncated() : env.final_mask();
    } else if (name == "info/config" || name == "final_info/config") {
      l.data = env.config_index();  // constant: a finished episode ran the same config
      l.dtype = kage::DType::kInt32;
    } else {
      const bool final = name.rfind("final_info/", 0) == 0;
      const std::string field = name.substr(name.find('/') + 1);
      int32_t count = 0;
      const kage::InfoFieldDesc* fields = kage::info_fields(&count);
      for (int32_t i = 0; i < count && !l.data; ++i) {
        if (field != fields[i].name) continue;
        l.data = final ? env.final_info(fields[i].field) : env.info(fields[i].field);
        l.dtype = fields[i].dtype;
      }
      if (!l.data) raise_value_error("no output named '" + name + "'");
    }
    return l;
  }

  static py::object export_array(const std::shared_ptr<kage::Env>& owner, const void* data,
                                 const std::vector<int64_t>& shape, kage::DType dtype) {
    if (owner->backend() == kage::Backend::kGpu) return py::cast(DeviceArray(owner, data, shape, dtype));
    // Host memory: a numpy view whose base keeps the batch alive.
    auto* keep = new std::shared_ptr<kage::Env>(owner);
    py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<kage::Env>*>(p); });
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t stride = static_cast<py::ssize_t>(facts(dtype).bytes);
    for (size_t i = shape.size(); i-- > 0;) {
      strides[i] = stride;
      stride *= shape[i];
    }
    return py::array(numpy_dtype(dtype), std::vector<py::ssize_t>(shape.begin(), shape.end()), strides, data, base);
  }

  /// Refuses an array of another element type than `expected`, rather than casting its values.
  static void check_dtype(const py::array& a, const char* what, bool ok, const char* expected) {
    if (!ok)
      raise_value_error(std::string(what) + ": " + expected + " values, got " + py::str(a.dtype()).cast<std::string>());
  }

  static void check_length(py::ssize_t got, int32_t n, const char* what) {
    if (got != n)
      raise_value_error(std::string(what) + ": expected " + std::to_string(n) + " values (one per environment), got " +
                        std::to_string(got));
  }

  /// A failed reset, step or synchronize, raised by the kind the runtime reports: an action outside 0..7 as
  /// the package's usage error class (ValueError), anything else as its other class (RuntimeError).
  static void raise_if_failed(const Outcome& o) {
    if (o.ok) return;
    const ErrorClasses& e = error_classes();
    const py::object& cls = o.kind == kage::ErrorKind::kAction ? e.usage : e.other;
    PyErr_SetObject(cls.ptr(), text(o.error).ptr());
    throw py::error_already_set();
  }

  static Outcome step_locked(kage::Env& e, const kage::Actions& a) {
    Outcome o;
    o.ok = e.step(a, &o.error);
    o.kind = e.last_error_kind();
    return o;
  }

  void run_step(const kage::Actions& a) {
    raise_if_failed(locked([&](kage::Env& e) { return step_locked(e, a); }));
  }

  std::shared_ptr<kage::Env> env_;
  std::shared_ptr<std::mutex> mutex_;  // shared: PyEnv is moved once, out of open_env
};

/// Raises `error` as the exception class of its kind.
[[noreturn]] void raise_kind(kage::ErrorKind kind, const std::string& error) {
  const ErrorClasses& e = error_classes();
  const py::object& cls = kind == kage::ErrorKind::kConfig   ? e.config
                          : kind == kage::ErrorKind::kFile   ? e.file
                          : kind == kage::ErrorKind::kDevice ? e.device
                          : kind == kage::ErrorKind::kUsage  ? e.usage
                                                             : e.other;
  PyErr_SetObject(cls.ptr(), text(error).ptr());
  throw py::error_already_set();
}

/// (the batch `open_fn(error, kind, warnings)` opens (without the GIL), its config's warnings as kagec prints
/// them), or its failure raised as the class of its kind.
template <class Open>
py::tuple opened(const Open& open_fn) {
  std::string error, warnings;
  kage::ErrorKind kind = kage::ErrorKind::kOther;
  std::unique_ptr<kage::Env> env;
  {
    py::gil_scoped_release release;
    env = open_fn(&error, &kind, &warnings);
  }
  if (!env) raise_kind(kind, error);
  return py::make_tuple(PyEnv(std::shared_ptr<kage::Env>(std::move(env))), text(warnings));
}

/// kage::compile_kernels without the GIL: (compiled, cached), or its failure raised as the class of its kind.
py::tuple compile_kernels(const std::vector<std::string>& paths, const std::string& asset_root) {
  kage::Options o;
  o.backend = kage::Backend::kGpu;
  o.asset_root = asset_root;
  std::string error;
  kage::ErrorKind kind = kage::ErrorKind::kOther;
  std::optional<kage::KernelsCompiled> done;
  {
    py::gil_scoped_release release;
    done = kage::compile_kernels(paths, o, &error, &kind);
  }
  if (!done) raise_kind(kind, error);
  return py::make_tuple(done->compiled, done->cached);
}

py::tuple open_env(const std::string& path, int32_t num_envs, const std::string& device, int32_t num_threads,
                   const std::string& asset_root, uintptr_t stream) {
  kage::Options o;
  o.backend = device == "cuda" ? kage::Backend::kGpu : kage::Backend::kCpu;
  o.num_envs = num_envs;
  o.num_threads = num_threads;
  o.asset_root = asset_root;
  o.stream = reinterpret_cast<void*>(stream);
  return opened([&](std::string* error, kage::ErrorKind* kind, std::string* warnings) {
    return kage::open(path, o, error, kind, warnings);
  });
}

py::tuple open_mixture(const std::vector<std::string>& paths, const std::vector<int32_t>& counts,
                       const std::string& device, int32_t num_threads, const std::string& asset_root,
                       uintptr_t stream) {
  if (paths.size() != counts.size()) raise_value_error("open_mixture: one environment count per config");
  std::vector<kage::MixturePart> parts;
  for (size_t k = 0; k < paths.size(); ++k) parts.push_back(kage::MixturePart{paths[k], counts[k]});
  kage::Options o;
  o.backend = device == "cuda" ? kage::Backend::kGpu : kage::Backend::kCpu;
  o.num_threads = num_threads;
  o.asset_root = asset_root;
  o.stream = reinterpret_cast<void*>(stream);
  return opened([&](std::string* error, kage::ErrorKind* kind, std::string* warnings) {
    return kage::open_mixture(parts, o, error, kind, warnings);
  });
}

/// The JSON of a front-end call, or its diagnostics raised as the config error class.
py::str front_end_json(const kage::python::FrontEndResult& r) {
  if (r.ok()) return text(r.json);
  PyErr_SetObject(error_classes().config.ptr(), text(r.error).ptr());
  throw py::error_already_set();
}

}  // namespace

PYBIND11_MODULE(_kage, m) {
  m.doc() = "Binding of the kage C++ API (include/kage/kage.h); use the kage package instead.";

  // open() raises these, by failure kind; the kage package names them (kage.ConfigError, ...).
  ErrorClasses& e = error_classes();
  e.config = py::reinterpret_borrow<py::object>(PyExc_ValueError);
  e.file = py::reinterpret_borrow<py::object>(PyExc_FileNotFoundError);
  e.device = py::reinterpret_borrow<py::object>(PyExc_RuntimeError);
  e.usage = py::reinterpret_borrow<py::object>(PyExc_ValueError);
  e.other = py::reinterpret_borrow<py::object>(PyExc_RuntimeError);
  m.def(
      "set_errors",
      [](py::object config, py::object file, py::object device, py::object usage, py::object other) {
        ErrorClasses& e = error_classes();
        e.config = std::move(config);
        e.file = std::move(file);
        e.device = std::move(device);
        e.usage = std::move(usage);
        e.other = std::move(other);
      },
      "Exception classes raised for a config, file, device, usage (an action outside 0..7 among them) and any "
      "other error, chosen by the runtime's error kind.");

  m.def("gpu_backend_built", &kage::gpu_backend_built);
  kage::python::register_paths(m);
  m.def("action_range_text", &kage::action_range_text, "The text in every error about an action outside 0..7.");
  m.def("resolve", [](const std::string& path, const std::string& asset_root) {
    return front_end_json(kage::python::resolve_config_json(path, asset_root));
  }, py::arg("path"), py::arg("asset_root") = "", "kagec resolve: the canonical Spec as JSON text.");
  m.def("lint", [](const std::string& path, const std::string& asset_root) {
    return text(kage::python::lint_text(path, asset_root));
  }, py::arg("path"), py::arg("asset_root") = "", "kagec lint: the config's diagnostics as text ('' when clean).");
  m.def("certify", [](const std::string& train, const std::string& eval, const std::string& asset_root) {
    return front_end_json(kage::python::certify_pair_json(train, eval, asset_root));
  }, py::arg("train"), py::arg("eval"), py::arg("asset_root") = "",
     "kagec diff --certify: the pair's certificate as JSON text.");
  m.def("certify_mixture", [](const std::vector<std::string>& paths, const std::string& asset_root) {
    return front_end_json(kage::python::certify_mixture_json(paths, asset_root));
  }, py::arg("paths"), py::arg("asset_root") = "", "kagec diff --mixture: the mixture's certificate as JSON text.");
  m.def("mixture_hash", [](const std::vector<std::string>& hashes, const std::vector<int32_t>& counts) {
    if (hashes.size() != counts.size()) raise_value_error("mixture_hash: one environment count per Spec hash");
    std::vector<std::pair<std::string, int32_t>> parts;
    for (size_t k = 0; k < hashes.size(); ++k) parts.emplace_back(hashes[k], counts[k]);
    return kage::python::mixture_hash(parts);
  }, py::arg("spec_hashes"), py::arg("counts"), "The spec hash of a mixture batch of these parts.");
  m.def("suite_report", [](const std::string& manifest) {
    return front_end_json(kage::python::suite_report(manifest));
  }, py::arg("manifest"), "kagec suite: the report of a manifest (pairs, sweeps, certificates) as JSON text.");
  m.def("info_fields", [] {
    int32_t count = 0;
    const kage::InfoFieldDesc* fields = kage::info_fields(&count);
    py::list out;
    for (int32_t i = 0; i < count; ++i) out.append(py::make_tuple(fields[i].name, numpy_dtype(fields[i].dtype), fields[i].doc));
    return out;
  }, "(name, numpy dtype, meaning) of every info field, in order.");
  m.def("open", &open_env, py::arg("path"), py::arg("num_envs"), py::arg("device"), py::arg("num_threads"),
        py::arg("asset_root"), py::arg("stream"), "kage::open: (the batch, its config's warnings as text).");
  m.def("step_rows", &PyEnv::step_rows, py::arg("envs"), py::arg("actions"),
        "Steps envs[i] with row i of actions (a 2-D numpy array, or a DLPack capsule ordered for envs[0]'s "
        "stream) in one call.");
  m.def("compile_kernels", &compile_kernels, py::arg("paths"), py::arg("asset_root"),
        "kage::compile_kernels: the configs' GPU kernels compiled into the kernel cache, side by side; "
        "(compiled, cached).");
  m.def("open_mixture", &open_mixture, py::arg("paths"), py::arg("counts"), py::arg("device"), py::arg("num_threads"),
        py::arg("asset_root"), py::arg("stream"), "kage::open_mixture: (the batch, its configs' warnings as text).");

  py::class_<DeviceArray>(m, "DeviceArray",
                          "A [N, ...] array in GPU memory, owned by an environment: take it with "
                          "torch.from_dlpack, jax.dlpack.from_dlpack or cupy.asarray (no copy), or copy it "
                          "to the host with .numpy(). Valid until the environment's next reset or step.")
      .def("__dlpack__", [](const DeviceArray& a, py::object stream, py::object, py::object, py::object) {
             return a.dlpack(stream);
           }, py::kw_only(), py::arg("stream") = py::none(), py::arg("max_version") = py::none(),
           py::arg("dl_device") = py::none(), py::arg("copy") = py::none())
      .def("__dlpack_device__", [](const DeviceArray&) { return py::make_tuple(static_cast<int>(kDLCUDA), 0); })
      .def_property_readonly("__cuda_array_interface__", &DeviceArray::cuda_array_interface)
      .def_property_readonly("shape", &DeviceArray::shape)
      .def_property_readonly("dtype", &DeviceArray::dtype)
      .def_property_readonly("data_ptr", &DeviceArray::data_ptr)
      .def_property_readonly("device", [](const DeviceArray&) { return "cuda:0"; })
      .def("numpy", &DeviceArray::numpy, "A host copy (waits for the environment's queued work).")
      .def("__repr__", [](const DeviceArray& a) {
        return "DeviceArray(shape=" + py::str(a.shape()).cast<std::string>() + ", dtype=" +
               py::str(a.dtype()).cast<std::string>() + ", device='cuda:0')";
      });

  py::class_<PyEnv>(m, "Env")
      .def("output", &PyEnv::output)
      .def("data_ptr", &PyEnv::data_ptr)
      .def("reset", &PyEnv::reset, py::arg("seeds"), py::arg("mask") = py::none())
      .def("step_host", &PyEnv::step_host)
      .def("step_device", &PyEnv::step_device)
      .def("step_dlpack", &PyEnv::step_dlpack)
      .def("save_state", &PyEnv::save_state)
      .def("load_state", &PyEnv::load_state)
      .def("synchronize", &PyEnv::synchronize)
      .def("pending_error", &PyEnv::pending_error)
      .def("close", &PyEnv::close)
      .def_property_readonly("closed", &PyEnv::closed)
      .def_property_readonly("num_envs", &PyEnv::num_envs)
      .def_property_readonly("height", &PyEnv::height)
      .def_property_readonly("width", &PyEnv::width)
      .def_property_readonly("spec_hash", &PyEnv::spec_hash)
      .def_property_readonly("device", &PyEnv::device)
      .def_property("stream", &PyEnv::stream, &PyEnv::set_stream);
}
