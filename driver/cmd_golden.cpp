// kagec golden check: replays the reference data recorded from the original (../shared/golden) through our
// configs, lowering and runtime, and prints the worst deviation per field or image against the README.
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <unistd.h>

#include "driver/cli_common.h"
#include "compiler/lower/load_lowered.h"
#include "verify/golden/golden_check.h"

namespace kage {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The original-format configs the render goldens were recorded with (golden/README.md, names from the
/// KAGE-Bench suite), as fixtures under --compat.
const std::map<std::string, std::string> kRenderConfigs = {
    {"shape_black", "agent_appearance/1-train.yaml"},
    {"line_black", "agent_appearance/1-eval.yaml"},
    {"color_red_layout", "layout/1-eval.yaml"},
    {"sprite_image", "filters/1-train.yaml"},
};

/// The original's repository-relative asset directory, as the original-format configs write it.
constexpr const char* kOriginalAssetDir = "src/kage_bench/assets";

struct GoldenContext {
  std::string configs;  // our golden configs (physics, filters, effects)
  std::string compat;   // original-format fixtures (render)
  std::string assets;   // the original's assets
  std::optional<fs::path> asset_root;  // temporary tree where kOriginalAssetDir resolves to `assets`
  CommandIo& io;
  std::vector<GoldenLine> lines;

  ~GoldenContext() {
    std::error_code ec;
    if (asset_root) fs::remove_all(*asset_root, ec);  // removes the link, never its target
  }

  void fail(const std::string& name, const std::string& why) { lines.push_back(GoldenLine{name, "-", 0, "-", false, why}); }

  /// A config through the front end and lowering; a failure is added to the report (under the file's
  /// name for front-end errors, under `what` for lowering's).
  LoweredFile load(const std::string& path, const std::optional<std::string>& root, const std::string& what) {
    SourceManager sources;
    DiagEngine diags(sources);
    DiskFileReader reader;
    ResolveOptions options;
    options.asset_root = root;
    LoweredFile loaded = load_lowered(path, options, sources, reader, diags);
    if (!loaded.spec) {
      std::ostringstream text;
      print_text(diags, text);
      fail(path, "config has errors:\n" + text.str());
    } else if (!loaded.ok()) {
      fail(what, loaded.lower_errors);
    }
    return loaded;
  }

  /// A Spec edited after loading, lowered again; a failure is added to the report under `what`.
  std::optional<LoweredConfig> lowered(const Spec& spec, const std::string& what) {
    LowerResult r = lower_spec(spec);
    if (!r.ok()) fail(what, r.error_text());
    return r.config;
  }

  /// Makes the temporary asset tree for the original-format configs.
  std::optional<std::string> original_root() {
    if (asset_root) return asset_root->string();
    std::error_code ec;
    const fs::path root = fs::temp_directory_path(ec) / ("kagec-golden-" + std::to_string(::getpid()));
    const fs::path link = root / kOriginalAssetDir;
    fs::create_directories(link.parent_path(), ec);
    if (!ec) fs::create_directory_symlink(fs::absolute(assets), link, ec);
    if (ec) {
      fail(assets, "cannot link the original's assets under " + root.string() + ": " + ec.message());
      return std::nullopt;
    }
    asset_root = root;
    return root.string();
  }

  std::optional<Spec> golden_default() {
    return load((fs::path(configs) / "default.yaml").string(), std::nullopt, "default").spec;
  }
};

std::optional<json> read_json(GoldenContext& ctx, const fs::path& path) {
  std::ifstream in(path);
  json j = in ? json::parse(in, nullptr, false) : json();
  if (!in || j.is_discarded()) {
    ctx.fail(path.string(), "cannot read it as JSON");
    return std::nullopt;
  }
  return j;
}

Image load_rgb(GoldenContext& ctx, const fs::path& path, bool& ok) {
  ImageResult r = load_image(path.string(), 3);
  ok = r.ok();
  if (!ok) ctx.fail(path.string(), r.error);
  return ok ? *r.image : Image{};
}

void check_physics_file(GoldenContext& ctx, const fs::path& file) {
  const std::optional<json> j = read_json(ctx, file);
  if (!j) return;
  const std::string config = j->value("config", "");
  const LoweredFile loaded = ctx.load((fs::path(ctx.configs) / (config + ".yaml")).string(), std::nullopt, config);
  const std::optional<LoweredConfig>& low = loaded.config;
  if (!low) return;
  for (GoldenLine& l : check_physics(file.filename().string(), low->latent, *j)) ctx.lines.push_back(std::move(l));
}

void check_render_dir(GoldenContext& ctx, const fs::path& dir) {
  const std::optional<json> meta = read_json(ctx, dir / "meta.json");
  if (!meta) return;
  const std::string config = meta->value("config", "");
  const auto it = kRenderConfigs.find(config);
  if (it == kRenderConfigs.end()) return ctx.fail(dir.string(), "no config is known for '" + config + "'");
  const std::optional<std::string> root = ctx.original_root();
  if (!root) return;
  const LoweredFile loaded = ctx.load((fs::path(ctx.compat) / it->second).string(), root, config);
  const std::optional<LoweredConfig>& low = loaded.config;
  if (!low) return;
  AssetPackResult pack = load_asset_pack(low->assets);
  if (!pack.ok()) return ctx.fail(dir.string(), pack.error);
  const ImageTolerance tol = low->visual.bg_mode == BackgroundMode::kImage ? kImageBackground : kExactImage;
  for (GoldenLine& l : check_render(dir.string(), low->latent, low->visual, pack.pack->view(), tol))
    ctx.lines.push_back(std::move(l));
}

/// The golden default's visual params with `settings` (key name -> value) written into the keys of
/// `axis`, lowered again; sized to `image`.
std::optional<VisualParams> with_settings(GoldenContext& ctx, const Spec& base, Axis axis, const json& settings,
                                          const Image& image, const std::string& what) {
  Spec spec = base;
  for (const auto& [name, value] : settings.items()) {
    const KeySchema* key = nullptr;
    for (const KeySchema& k : config_schema().keys())
      if (k.axis == axis && k.name == name && k.alias_of.empty()) key = &k;
    if (!key) {
      ctx.fail(what, "setting '" + name + "' is not a key of the " + axis_name(axis) + " axis");
      return std::nullopt;
    }
    spec.values[key->section][key->name] = value;
    spec.inert.erase(key->path);
  }
  std::optional<LoweredConfig> low = ctx.lowered(spec, what);
  if (!low) return std::nullopt;
  low->visual.H = image.height;
  low->visual.W = image.width;
  return low->visual;
}

void check_filters_dir(GoldenContext& ctx, const fs::path& dir) {
  const std::optional<json> index = read_json(ctx, dir / "index.json");
  const std::optional<Spec> base = ctx.golden_default();
  bool ok = false;
  const Image input = load_rgb(ctx, dir / "base.png", ok);
  if (!index || !base || !ok) return;
  for (const auto& [name, settings] : index->items()) {
    const std::string what = "filters/" + name + ".png";
    const std::optional<VisualParams> p = with_settings(ctx, *base, Axis::Filters, settings, input, what);
    const Image expected = load_rgb(ctx, dir / (name + ".png"), ok);
    if (!p || !ok) continue;
    Image got = input;
    apply_filter_chain(*p, got);
    ctx.lines.push_back(compare_image(what, got.pixels.data(), expected, kFilterImage));
  }
}

void check_effects_dir(GoldenContext& ctx, const fs::path& dir) {
  const std::optional<json> index = read_json(ctx, dir / "index.json");
  const std::optional<Spec> base = ctx.golden_default();
  if (!index || !base) return;
  for (const auto& [name, c] : index->items()) {
    const std::string what = "effects/" + name + "_lit.png";
    bool ok_unlit = false, ok_lit = false;
    const Image unlit = load_rgb(ctx, dir / (name + "_unlit.png"), ok_unlit);
    const Image lit = load_rgb(ctx, dir / (name + "_lit.png"), ok_lit);
    if (!ok_unlit || !ok_lit) continue;
    const std::optional<VisualParams> p = with_settings(ctx, *base, Axis::Effects, c.at("effects"), unlit, what);
    if (!p) continue;
    float x[kMaxLights] = {}, y[kMaxLights] = {};
    const json& pos = c.at("light_positions");
    for (int i = 0; i < kMaxLights && i < static_cast<int>(pos.size()); ++i) {
      x[i] = pos[i][0].get<float>();
      y[i] = pos[i][1].get<float>();
    }
    Image got = unlit;
    apply_point_lights(*p, x, y, got);
    ctx.lines.push_back(compare_image(what, got.pixels.data(), lit, kFilterImage));
  }
}

/// Dispatches one path: a golden folder (everything in it), a physics file, or one of the folders.
void check_path(GoldenContext& ctx, const fs::path& path) {
  const std::string name = path.filename().string();
  if (fs::is_regular_file(path) && name.rfind("physics_", 0) == 0) return check_physics_file(ctx, path);
  if (!fs::is_directory(path)) return ctx.fail(path.string(), "not a golden file or folder");
  if (fs::exists(path / "meta.json")) return check_render_dir(ctx, path);
  if (name == "filters") return check_filters_dir(ctx, path);
  if (name == "effects") return check_effects_dir(ctx, path);
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(path)) entries.push_back(e.path());
  std::sort(entries.begin(), entries.end());
  const size_t before = ctx.lines.size();
  for (const fs::path& e : entries) {
    const std::string n = e.filename().string();
    if (n.rfind("physics_", 0) == 0 || n.rfind("render_", 0) == 0 || n == "filters" || n == "effects") check_path(ctx, e);
  }
  if (ctx.lines.size() == before) ctx.fail(path.string(), "holds no golden data (physics_*.json, render_*/, filters/, effects/)");
}

void print_report(const std::vector<GoldenLine>& lines, std::ostream& out) {
  for (const GoldenLine& l : lines) {
    out << (l.pass ? "PASS  " : "FAIL  ") << std::left << std::setw(44) << l.name << " " << l.measure << " "
        << l.worst << " (limit " << l.limit << ")";
    if (!l.detail.empty()) out << "  " << l.detail;
    out << "\n";
  }
}

}  // namespace

int cmd_golden(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Check the runtime against the reference data recorded from the original.", "golden");
  app.require_subcommand(1);
  CLI::App* check = app.add_subcommand("check", "replay golden files and compare them at the README tolerances");
  std::vector<std::string> paths;
  std::string configs = "configs/golden", compat = "tests/compat/original", shared = "../shared";
  check->add_option("paths", paths, "golden files or folders (e.g. ../shared/golden)")->required();
  check->add_option("--configs", configs, "folder of our golden configs (default.yaml, variant.yaml)");
  check->add_option("--compat", compat, "folder of the original-format configs the render goldens use");
  check->add_option("--shared", shared, "shared folder whose kage-assets/ holds the original's assets");
  if (auto code = parse_args(app, args, io)) return *code;
  GoldenContext ctx{configs, compat, (fs::path(shared) / "kage-assets").string(), std::nullopt, io, {}};
  for (const std::string& p : paths) check_path(ctx, fs::path(p));
  print_report(ctx.lines, io.out);
  const size_t failed = std::count_if(ctx.lines.begin(), ctx.lines.end(), [](const GoldenLine& l) { return !l.pass; });
  io.out << ctx.lines.size() << " checks, " << failed << " failed\n";
  return failed == 0 ? kExitOk : kExitErrors;
}

}  // namespace kage
