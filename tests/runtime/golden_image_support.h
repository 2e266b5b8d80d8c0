// Shared by the image golden tests: load a recorded PNG as RGB or fail the test with the loader's error.
#pragma once

#include <catch2/catch.hpp>
#include <string>

#include "fileio/image_io.h"

namespace kage::test {

inline Image load_rgb(const std::string& path) {
  ImageResult r = load_image(path, 3);
  INFO(r.error);
  REQUIRE(r.ok());
  return *r.image;
}

}  // namespace kage::test
