// kage_assetgen entry point: `kage_assetgen [OUT_DIR]` (default: assets).
#include <iostream>

#include "tools/assetgen/assetgen.h"

int main(int argc, char** argv) {
  if (argc > 2) {
    std::cerr << "usage: kage_assetgen [OUT_DIR]\n";
    return 2;
  }
  return kage::assetgen::run_assetgen(argc == 2 ? argv[1] : "assets", std::cerr);
}
