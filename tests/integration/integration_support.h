// Shared helpers of the integration tests: repository paths and temporary config files.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace kage::test {

inline const std::string kRoot = KAGE_SOURCE_DIR;

/// A config file in a fresh temporary folder, removed with the object.
class TempConfig {
 public:
  TempConfig(const std::string& name, const std::string& text)
      : dir_(std::filesystem::temp_directory_path() / ("kage-integration-" + name)) {
    std::filesystem::create_directories(dir_);
    std::ofstream(path()) << text;
  }
  ~TempConfig() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  std::string path() const { return (dir_ / "config.yaml").string(); }

 private:
  std::filesystem::path dir_;
};

/// `extends:` line naming the golden default config by absolute path.
inline std::string extends_golden_default() { return "extends: " + kRoot + "/configs/golden/default.yaml\n"; }

}  // namespace kage::test
