// Codegen: lowered parameters -> one specialized source file (templates/kernels.cu.in) whose
// config type defines LatentParams and VisualParams as constexpr values for the shared kernels.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/latent/latent_params.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Bumped whenever the generated text changes for the same inputs and templates.
inline constexpr int kCodegenVersion = 2;

/// What the generator reads: the Spec's hash and its lowered parameters.
struct CodegenInput {
  std::string spec_hash;  ///< 64 hex digits (Spec::sha256)
  LatentParams latent{};
  VisualParams visual{};
};

/// The generated file's name for a Spec hash (64 hex digits): kage_<first 16>.cu. NVRTC's diagnostics name it,
/// also for a source read back from a compile directory.
std::string generated_file_name(const std::string& spec_hash);

/// One generated file and the facts a manifest or a certificate records about it.
struct GeneratedSource {
  std::string file_name;       ///< kage_<first 16 hex of the spec hash>.cu
  std::string config_name;     ///< KageConfig_<first 16 hex>
  std::string text;            ///< the whole file
  std::string latent_section;  ///< the dynamics part, embedded verbatim in `text`
  std::string latent_hash;     ///< SHA-256 of latent_section
  std::string template_hash;   ///< SHA-256 over the templates the text came from
};

/// The object bytes of a parameter struct as little-endian 32-bit words (padding as lowering left it:
/// zero, because lowering value-initializes the structs).
std::vector<uint32_t> param_words(const LatentParams& p);
std::vector<uint32_t> param_words(const VisualParams& p);

/// SHA-256 over the embedded templates (names and texts).
std::string template_hash();

/// The latent section alone: a pure function of the latent parameters and the template.
std::string generate_latent_section(const LatentParams& p);

/// The whole file; the same input always gives byte-identical text.
GeneratedSource generate_source(const CodegenInput& in);

// Embedded template texts (generated at build time from templates/).
const std::string& kernels_cu_template_text();
const std::string& latent_section_inc_template_text();

}  // namespace kage
