// The buffers of kage.jax's FFI calls: counted, checked against the config, turned into row pointers.
#include "api/jax/ffi_buffers.h"

#include <optional>
#include <string>
#include <type_traits>

namespace kage::jax {
namespace ffi = xla::ffi;
namespace {

/// What the elements of a buffer must be.
enum class Elem { kByte, kWord, kFloat, kInt32, kFlag };

template <class T>
constexpr Elem elem_of() {
  if constexpr (std::is_same_v<T, float>) return Elem::kFloat;
  else if constexpr (std::is_same_v<T, int32_t>) return Elem::kInt32;
  else return Elem::kFlag;  // the uint8_t 0/1 columns: uint8 or bool on the JAX side
}

bool fits(Elem e, ffi::DataType t) {
  switch (e) {
    case Elem::kByte: return t == ffi::DataType::U8;
    case Elem::kWord: return t == ffi::DataType::U32;
    case Elem::kFloat: return t == ffi::DataType::F32;
    case Elem::kInt32: return t == ffi::DataType::S32;
    case Elem::kFlag: return t == ffi::DataType::U8 || t == ffi::DataType::PRED;
  }
  return false;
}

const char* elem_name(Elem e) {
  switch (e) {
    case Elem::kByte: return "uint8";
    case Elem::kWord: return "uint32";
    case Elem::kFloat: return "float32";
    case Elem::kInt32: return "int32";
    case Elem::kFlag: return "uint8 or bool";
  }
  return "?";
}

/// Takes a call's buffers, checking that each holds `n` environments of `bytes` bytes of elements `e`;
/// the first problem goes to `error` (and its pointer is null).
class Taker {
 public:
  Taker(const ffi::RemainingArgs& args, const ffi::RemainingRets& rets) : args_(args), rets_(rets) {}

  int64_t n = 0;
  std::string error;

  bool counts(size_t want_args, size_t want_rets) {
    if (args_.size() == want_args && rets_.size() == want_rets) return true;
    error = std::to_string(args_.size()) + " arguments and " + std::to_string(rets_.size()) + " results, expected " +
            std::to_string(want_args) + " and " + std::to_string(want_rets) +
            " (kage.jax's Python modules and its extension _kage_jax come from different builds: reinstall)";
    return false;
  }

  /// Sets `n` from argument i, which holds `per_env` elements per environment.
  bool count_envs(size_t i, int64_t per_env) {
    const ffi::ErrorOr<ffi::AnyBuffer> b = args_.get<ffi::AnyBuffer>(i);
    if (!b.has_value() || b->element_count() % per_env != 0) {
      error = "argument " + std::to_string(i) + " is not a buffer of " + std::to_string(per_env) +
              " elements per environment";
      return false;
    }
    n = static_cast<int64_t>(b->element_count()) / per_env;
    return true;
  }

  template <class T>
  T* arg(size_t i, const char* name, Elem e, size_t bytes) {
    const ffi::ErrorOr<ffi::AnyBuffer> b = args_.get<ffi::AnyBuffer>(i);
    if (!b.has_value()) return fail<T>("argument", i, name, "is not a buffer");
    return check<T>(*b, "argument", i, name, e, bytes);
  }

  template <class T>
  T* ret(size_t i, const char* name, Elem e, size_t bytes) {
    ffi::ErrorOr<ffi::Result<ffi::AnyBuffer>> b = rets_.get<ffi::AnyBuffer>(i);
    if (!b.has_value()) return fail<T>("result", i, name, "is not a buffer");
    return check<T>(**b, "result", i, name, e, bytes);
  }

  /// The info columns at arguments (or results) first .. first + kInfoFieldCount - 1.
  InfoArrays info(size_t first, bool from_args) {
    InfoArrays a{};
    size_t i = first;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value)                                         \
  a.member = from_args ? arg<ctype>(i, name, elem_of<ctype>(), sizeof(ctype)) \
                       : ret<ctype>(i, name, elem_of<ctype>(), sizeof(ctype));                                \
  ++i;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
    return a;
  }

 private:
  template <class T>
  T* fail(const char* kind, size_t i, const char* name, const std::string& what) {
    if (error.empty()) error = std::string(kind) + " " + std::to_string(i) + " (" + name + ") " + what;
    return nullptr;
  }

  template <class T>
  T* check(const ffi::AnyBuffer& b, const char* kind, size_t i, const char* name, Elem e, size_t bytes) {
    if (!fits(e, b.element_type())) return fail<T>(kind, i, name, std::string("is not ") + elem_name(e));
    if (b.size_bytes() != static_cast<size_t>(n) * bytes)
      return fail<T>(kind, i, name,
                     "holds " + std::to_string(b.size_bytes()) + " bytes, expected " + std::to_string(n) +
                         " environments x " + std::to_string(bytes));
    return static_cast<T*>(b.untyped_data());
  }

  const ffi::RemainingArgs& args_;
  const ffi::RemainingRets& rets_;
};

/// The results both calls have: the state (from `first_state`), then from `first_obs` the observations,
/// reward, flags and final mask.
void take_outputs(Taker& t, const JaxConfig& c, size_t first_state, size_t first_obs, EnvBuffers* b) {
  b->latent = t.ret<LatentState>(first_state, "latent", Elem::kByte, sizeof(LatentState));
  b->segments = t.ret<uint8_t>(first_state + 1, "segments", Elem::kByte, static_cast<size_t>(c.segment_stride));
  b->visual = t.ret<VisualState>(first_state + 2, "visual", Elem::kByte, sizeof(VisualState));
  b->obs = t.ret<uint8_t>(first_obs, "obs", Elem::kByte, c.frame_bytes());
  b->reward = t.ret<float>(first_obs + 1, "reward", Elem::kFloat, sizeof(float));
  b->terminated = t.ret<uint8_t>(first_obs + 2, "terminated", Elem::kFlag, 1);
  b->truncated = t.ret<uint8_t>(first_obs + 3, "truncated", Elem::kFlag, 1);
  b->final_mask = t.ret<uint8_t>(first_obs + 4, "final_mask", Elem::kFlag, 1);
}

/// Argument `a` and result `r`'s buffers when they are not one buffer, to be copied from `a` to `r`; an error
/// when their sizes differ.
std::optional<InPlaceCopy> unaliased(const ffi::RemainingArgs& args, const ffi::RemainingRets& rets, size_t a,
                                     size_t r, std::string* error) {
  ffi::ErrorOr<ffi::AnyBuffer> in = args.get<ffi::AnyBuffer>(a);
  ffi::ErrorOr<ffi::Result<ffi::AnyBuffer>> out = rets.get<ffi::AnyBuffer>(r);
  if (!in.has_value() || !out.has_value() || in->size_bytes() != (**out).size_bytes()) {
    *error = "argument " + std::to_string(a) + " does not match result " + std::to_string(r) +
             ", which it updates in place";
    return std::nullopt;
  }
  if (in->untyped_data() == (**out).untyped_data()) return std::nullopt;
  return InPlaceCopy{(**out).untyped_data(), in->untyped_data(), in->size_bytes()};
}

}  // namespace

ffi::Error handler_error(const char* call, const std::string& what) {
  return ffi::Error::InvalidArgument(std::string("kage.jax: ") + call + ": " + what);
}

ffi::ErrorOr<EnvBuffers> reset_buffers(const JaxConfig& c, const ffi::RemainingArgs& args,
                                       const ffi::RemainingRets& rets) {
  Taker t(args, rets);
  EnvBuffers b;
  if (t.counts(1, 8 + kInfoFieldCount) && t.count_envs(0, 2)) {
    b.n = t.n;
    b.seeds = t.arg<const uint64_t>(0, "seeds", Elem::kWord, sizeof(uint64_t));
    take_outputs(t, c, 0, 3, &b);
    b.info = t.info(8, false);
  }
  if (!t.error.empty()) return ffi::Unexpected(handler_error("kage_reset", t.error));
  return b;
}

ffi::ErrorOr<EnvBuffers> step_buffers(const JaxConfig& c, const ffi::RemainingArgs& args,
                                      const ffi::RemainingRets& rets) {
  constexpr size_t kFinalInfoArg = 6, kFinalInfoRet = 12, kInfoRet = kFinalInfoRet + kInfoFieldCount;
  Taker t(args, rets);
  EnvBuffers b;
  if (t.counts(kFinalInfoArg + kInfoFieldCount, kInfoRet + kInfoFieldCount) && t.count_envs(5, 1)) {
    b.n = t.n;
    b.seeds = t.arg<const uint64_t>(0, "seeds", Elem::kWord, sizeof(uint64_t));
    b.actions = t.arg<const int32_t>(5, "actions", Elem::kInt32, sizeof(int32_t));
    take_outputs(t, c, 0, 4, &b);
    b.final_obs = t.ret<uint8_t>(3, "final_obs", Elem::kByte, c.frame_bytes());
    b.final_latent = t.ret<LatentState>(9, "final_latent", Elem::kByte, sizeof(LatentState));
    b.final_segments = t.ret<uint8_t>(10, "final_segments", Elem::kByte, static_cast<size_t>(c.segment_stride));
    b.final_visual = t.ret<VisualState>(11, "final_visual", Elem::kByte, sizeof(VisualState));
    b.final_info = t.info(kFinalInfoRet, false);
    b.info = t.info(kInfoRet, false);
    // The state is updated in place. input_output_aliases asks XLA for one buffer per pair, and it mostly
    // gives one; where it does not (seen on the GPU inside a scan), the result starts as a copy of the input.
    for (size_t i = 0; i < kInPlacePairs && t.error.empty(); ++i) {
      const size_t a = i < 4 ? 1 + i : kFinalInfoArg + (i - 4), r = i < 4 ? i : kFinalInfoRet + (i - 4);
      if (std::optional<InPlaceCopy> copy = unaliased(args, rets, a, r, &t.error)) b.copies[b.copy_count++] = *copy;
    }
  }
  if (!t.error.empty()) return ffi::Unexpected(handler_error("kage_step", t.error));
  return b;
}

}  // namespace kage::jax
