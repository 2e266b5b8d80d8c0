// The saved state of a batch of environments (kage::Env::save_state): a header, then the state and the
// last outputs of every environment, section by section. One format for every backend, so a batch saved
// on the GPU restores on the CPU and the other way round.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "runtime/episode_info.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Fixed-size header at the start of a saved state.
struct BatchStateHeader {
  char magic[8];             ///< "KAGEBST\0"
  uint32_t version;          ///< kBatchStateVersion
  int32_t num_envs;
  int32_t segment_bytes;     ///< layout bytes per environment
  uint32_t latent_bytes;     ///< sizeof(LatentState) of the writer
  uint32_t visual_bytes;     ///< sizeof(VisualState) of the writer
  uint32_t reserved;
  char spec_hash[64];        ///< SHA-256 hex of the configuration's Spec
};
static_assert(sizeof(BatchStateHeader) == 96, "BatchStateHeader layout changed");

inline constexpr uint32_t kBatchStateVersion = 1;
inline constexpr char kBatchStateMagic[8] = {'K', 'A', 'G', 'E', 'B', 'S', 'T', '\0'};

/// Byte offsets of the sections of a saved state of `n` environments with `segment_bytes` of layout each.
struct BatchStateLayout {
  size_t seeds, latent, segments, visual, reward, terminated, truncated;
  size_t info[kInfoFieldCount];  ///< one per info field, in runtime/info_fields.def order
  size_t total;

  BatchStateLayout(size_t n, size_t segment_bytes) {
    size_t at = sizeof(BatchStateHeader);
    auto take = [&](size_t bytes) {
      const size_t off = at;
      at += (bytes + 7) / 8 * 8;
      return off;
    };
    seeds = take(n * sizeof(uint64_t));
    latent = take(n * sizeof(LatentState));
    segments = take(n * segment_bytes);
    visual = take(n * sizeof(VisualState));
    reward = take(n * sizeof(float));
    terminated = take(n);
    truncated = take(n);
    int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) info[i++] = take(n * sizeof(ctype));
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
    total = at;
  }
};

/// Writes the header of a state of `num_envs` environments into `out` (sizeof(BatchStateHeader) bytes).
inline void write_batch_state_header(uint8_t* out, int32_t num_envs, int32_t segment_bytes, const std::string& spec_hash) {
  BatchStateHeader h{};
  std::memcpy(h.magic, kBatchStateMagic, sizeof h.magic);
  h.version = kBatchStateVersion;
  h.num_envs = num_envs;
  h.segment_bytes = segment_bytes;
  h.latent_bytes = sizeof(LatentState);
  h.visual_bytes = sizeof(VisualState);
  std::memcpy(h.spec_hash, spec_hash.data(), spec_hash.size() < sizeof h.spec_hash ? spec_hash.size() : sizeof h.spec_hash);
  std::memcpy(out, &h, sizeof h);
}

/// Why `data` (size bytes) cannot be loaded into a batch of `num_envs` environments of the config with
/// `spec_hash` and `segment_bytes` of layout; empty when it can.
inline std::string check_batch_state(const uint8_t* data, size_t size, int32_t num_envs, int32_t segment_bytes,
                                     const std::string& spec_hash) {
  BatchStateHeader h{};
  if (size < sizeof h) return "the saved state is " + std::to_string(size) + " bytes, shorter than its header";
  std::memcpy(&h, data, sizeof h);
  if (std::memcmp(h.magic, kBatchStateMagic, sizeof h.magic) != 0) return "not a saved kage batch state (bad magic)";
  if (h.version != kBatchStateVersion || h.latent_bytes != sizeof(LatentState) || h.visual_bytes != sizeof(VisualState))
    return "the saved state has format version " + std::to_string(h.version) + " (state sizes " +
           std::to_string(h.latent_bytes) + "/" + std::to_string(h.visual_bytes) + "); this build reads version " +
           std::to_string(kBatchStateVersion) + " (" + std::to_string(sizeof(LatentState)) + "/" +
           std::to_string(sizeof(VisualState)) + "): restore it with the kage version that saved it";
  const std::string saved_hash(h.spec_hash, strnlen(h.spec_hash, sizeof h.spec_hash));
  if (saved_hash != spec_hash)
    return "the state was saved from the config with spec hash " + saved_hash + ", but this environment runs " +
           spec_hash + ": open the config it was saved from";
  if (h.num_envs != num_envs)
    return "the state holds " + std::to_string(h.num_envs) + " environments, this batch has " +
           std::to_string(num_envs) + ": open it with num_envs=" + std::to_string(h.num_envs);
  if (h.segment_bytes != segment_bytes) return "the saved layout size differs from this config's";
  const size_t want = BatchStateLayout(static_cast<size_t>(num_envs), static_cast<size_t>(segment_bytes)).total;
  if (size != want) return "the saved state is " + std::to_string(size) + " bytes, expected " + std::to_string(want);
  return {};
}

}  // namespace kage
