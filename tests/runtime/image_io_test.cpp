// Tests for fileio/ image I/O and the runtime/io GIF writer: decoding errors, PNG round trip, the GIF
// encoder (decoded back with stb_image) and the Lanczos resampler.
#include <catch2/catch.hpp>
#include <stb/stb_image.h>

#include <sys/resource.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "runtime/io/gif_writer.h"
#include "fileio/image_io.h"

namespace {

namespace fs = std::filesystem;

std::string temp_dir() {
  const fs::path dir = fs::temp_directory_path() / "kage_image_io_test";
  fs::create_directories(dir);
  return dir.string();
}

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A deterministic test pattern with smooth and sharp regions.
kage::Image pattern(int w, int h, int channels) {
  kage::Image img{w, h, channels, std::vector<uint8_t>(size_t(w) * h * channels)};
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = uint8_t(x * 255 / (w - 1));
      p[1] = uint8_t(y * 255 / (h - 1));
      p[2] = uint8_t(((x / 4 + y / 4) % 2) ? 230 : 20);
      if (channels == 4) p[3] = uint8_t((x + y) % 3 == 0 ? 0 : (x % 2 ? 255 : 128));
    }
  }
  return img;
}

}  // namespace

TEST_CASE("load_image reports a missing file by name", "[image_io]") {
  const std::string path = temp_dir() + "/does_not_exist.png";
  const kage::ImageResult r = kage::load_image(path, 4);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kMissing);
  CHECK(r.error.find(path) == 0);
  CHECK(r.error.find("no such file") != std::string::npos);
}

TEST_CASE("load_image rejects garbage, empty files and directories", "[image_io]") {
  const std::string dir = temp_dir();
  const std::string garbage = dir + "/garbage.png";
  write_bytes(garbage, {'n', 'o', 't', ' ', 'a', 'n', ' ', 'i', 'm', 'a', 'g', 'e', 0x00, 0x13});
  kage::ImageResult r = kage::load_image(garbage, 4);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kUnsupported);
  CHECK(r.error.find(garbage) == 0);

  // Right signature, broken body.
  const std::string bad_png = dir + "/bad_body.png";
  std::vector<uint8_t> bytes = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  for (int i = 0; i < 40; ++i) bytes.push_back(uint8_t(i * 37));
  bytes.insert(bytes.end(), {'I', 'E', 'N', 'D', 0, 0, 0, 0});
  write_bytes(bad_png, bytes);
  r = kage::load_image(bad_png, 4);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kCorrupt);
  CHECK(r.error.find(bad_png) == 0);
  CHECK(r.error.find("corrupt PNG") != std::string::npos);

  const std::string empty = dir + "/empty.jpeg";
  write_bytes(empty, {});
  r = kage::load_image(empty, 3);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kEmpty);
  CHECK(r.error.find(empty) == 0);

  r = kage::load_image(dir, 3);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kUnreadable);
}

TEST_CASE("PNG round trip is exact; truncation is detected", "[image_io]") {
  const std::string path = temp_dir() + "/roundtrip.png";
  const kage::Image img = pattern(17, 9, 4);
  REQUIRE(kage::write_png(path, img).ok());
  const kage::ImageResult r = kage::load_image(path, 4);
  REQUIRE(r.ok());
  CHECK(r.image->width == 17);
  CHECK(r.image->height == 9);
  CHECK(r.image->pixels == img.pixels);

  // RGBA -> RGB drops alpha (Pillow's convert("RGB")).
  const kage::ImageResult rgb = kage::load_image(path, 3);
  REQUIRE(rgb.ok());
  CHECK(rgb.image->channels == 3);
  CHECK(rgb.image->at(5, 3)[1] == img.at(5, 3)[1]);

  std::vector<uint8_t> bytes = read_bytes(path);
  bytes.resize(bytes.size() / 2);
  const std::string cut = temp_dir() + "/cut.png";
  write_bytes(cut, bytes);
  const kage::ImageResult c = kage::load_image(cut, 4);
  REQUIRE_FALSE(c.ok());
  CHECK(c.kind == kage::ImageError::kCorrupt);
  CHECK(c.error.find(cut) == 0);
}

TEST_CASE("a truncated JPEG is an error naming the file", "[image_io]") {
  const std::string path = temp_dir() + "/full.jpeg";
  REQUIRE(kage::write_jpeg(path, pattern(64, 64, 3), 90).ok());
  const kage::ImageResult ok = kage::load_image(path, 3);
  REQUIRE(ok.ok());
  CHECK(ok.image->width == 64);

  std::vector<uint8_t> bytes = read_bytes(path);
  bytes.resize(bytes.size() * 2 / 3);
  const std::string cut = temp_dir() + "/truncated.jpeg";
  write_bytes(cut, bytes);
  const kage::ImageResult r = kage::load_image(cut, 3);
  REQUIRE_FALSE(r.ok());
  CHECK(r.kind == kage::ImageError::kCorrupt);
  CHECK(r.error.find(cut) == 0);
  CHECK(r.error.find("truncated") != std::string::npos);
}

TEST_CASE("GIF frames decode back within palette error", "[gif]") {
  std::vector<kage::Image> frames;
  for (int f = 0; f < 3; ++f) {
    kage::Image img = pattern(40, 30, 3);
    for (size_t i = 0; i < img.pixels.size(); i += 3) img.pixels[i] = uint8_t(img.pixels[i] + 60 * f);
    frames.push_back(img);
  }
  std::string error;
  const std::vector<uint8_t> gif = kage::encode_gif(frames, 5, &error);
  REQUIRE(error.empty());
  REQUIRE(gif.size() > 800);

  int w = 0, h = 0, z = 0, n = 0;
  int* delays = nullptr;
  stbi_uc* px = stbi_load_gif_from_memory(gif.data(), int(gif.size()), &delays, &w, &h, &z, &n, 3);
  REQUIRE(px != nullptr);
  CHECK(w == 40);
  CHECK(h == 30);
  REQUIRE(z == 3);
  CHECK(delays[0] == 50);  // milliseconds
  int worst = 0;
  long nonzero = 0;
  for (int f = 0; f < z; ++f) {
    const uint8_t* got = px + size_t(f) * w * h * 3;
    for (size_t i = 0; i < frames[f].pixels.size(); ++i) {
      const uint8_t want = frames[f].pixels[i];
      worst = std::max(worst, std::abs(int(got[i]) - int(want)));
      nonzero += got[i] != 0;
      // The decoded value is exactly the palette colour of the source pixel.
      const size_t p = i / 3 * 3;
      uint8_t rgb[3];
      kage::gif_palette_color(kage::gif_palette_index(frames[f].pixels[p], frames[f].pixels[p + 1],
                                                      frames[f].pixels[p + 2]), rgb);
      REQUIRE(int(got[i]) == int(rgb[i - p]));
    }
  }
  stbi_image_free(px);
  stbi_image_free(delays);
  CHECK(worst <= 26);  // half a step of the 6-level channels
  CHECK(nonzero > 1000);
}

TEST_CASE("GIF LZW survives dictionary resets on a large noisy frame", "[gif]") {
  kage::Image img{300, 200, 3, std::vector<uint8_t>(300 * 200 * 3)};
  uint32_t s = 12345;
  for (auto& v : img.pixels) {
    s = s * 1664525u + 1013904223u;
    v = uint8_t(s >> 24);
  }
  const std::string path = temp_dir() + "/noise.gif";
  REQUIRE(kage::write_gif(path, {img}, 10).ok());
  int w = 0, h = 0, n = 0;
  stbi_uc* px = stbi_load(path.c_str(), &w, &h, &n, 3);
  REQUIRE(px != nullptr);
  REQUIRE(w == 300);
  bool exact = true;
  for (size_t i = 0; i < img.pixels.size(); i += 3) {
    uint8_t rgb[3];
    kage::gif_palette_color(kage::gif_palette_index(img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]), rgb);
    exact = exact && px[i] == rgb[0] && px[i + 1] == rgb[1] && px[i + 2] == rgb[2];
  }
  stbi_image_free(px);
  CHECK(exact);
}

TEST_CASE("Lanczos resize keeps flat colour, skips unchanged axes", "[lanczos]") {
  kage::Image flat{50, 40, 3, std::vector<uint8_t>(50 * 40 * 3)};
  for (size_t i = 0; i < flat.pixels.size(); i += 3) {
    flat.pixels[i] = 200;
    flat.pixels[i + 1] = 17;
    flat.pixels[i + 2] = 99;
  }
  const kage::Image out = kage::resize_lanczos(flat, 33, 128);
  REQUIRE(out.width == 33);
  REQUIRE(out.height == 128);
  for (size_t i = 0; i < out.pixels.size(); i += 3) {
    REQUIRE(int(out.pixels[i]) == 200);
    REQUIRE(int(out.pixels[i + 1]) == 17);
    REQUIRE(int(out.pixels[i + 2]) == 99);
  }
  const kage::Image same = kage::resize_lanczos(pattern(20, 10, 3), 20, 10);
  CHECK(same.pixels == pattern(20, 10, 3).pixels);
  // Width only: rows are resampled independently.
  const kage::Image wide = kage::resize_lanczos(pattern(20, 10, 3), 40, 10);
  CHECK(wide.width == 40);
  CHECK(int(wide.at(0, 0)[1]) == 0);
}

namespace {

uint64_t peak_rss_bytes() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return uint64_t(u.ru_maxrss) * 1024;
}

void put_be(std::vector<uint8_t>& out, uint32_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(uint8_t(v >> (8 * i)));
}
void put_le(std::vector<uint8_t>& out, uint32_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

/// Headers of each format claiming `w` x `h` pixels (and nothing else of note).
std::vector<uint8_t> png_claiming(uint32_t w, uint32_t h) {
  std::vector<uint8_t> b = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  put_be(b, 13, 4);
  b.insert(b.end(), {'I', 'H', 'D', 'R'});
  put_be(b, w, 4);
  put_be(b, h, 4);
  b.insert(b.end(), {8, 2, 0, 0, 0, 0, 0, 0, 0});
  put_be(b, 0, 4);
  b.insert(b.end(), {'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82});
  return b;
}
std::vector<uint8_t> bmp_claiming(uint32_t w, uint32_t h) {
  std::vector<uint8_t> b = {'B', 'M'};
  put_le(b, 54, 4);
  put_le(b, 0, 4);
  put_le(b, 54, 4);
  put_le(b, 40, 4);
  put_le(b, w, 4);
  put_le(b, uint32_t(-int32_t(h)), 4);  // top-down
  put_le(b, 1, 2);
  put_le(b, 24, 2);
  b.resize(54, 0);
  return b;
}
std::vector<uint8_t> gif_claiming(uint16_t w, uint16_t h) {
  std::vector<uint8_t> b = {'G', 'I', 'F', '8', '9', 'a'};
  put_le(b, w, 2);
  put_le(b, h, 2);
  b.insert(b.end(), {0, 0, 0, ';'});
  return b;
}
std::vector<uint8_t> jpeg_claiming(uint16_t w, uint16_t h) {
  std::vector<uint8_t> b = {0xFF, 0xD8, 0xFF, 0xE0};  // SOI, then an APP0 segment before the frame
  put_be(b, 16, 2);
  b.insert(b.end(), {'J', 'F', 'I', 'F', 0, 1, 1, 0, 0, 1, 0, 1, 0, 0});
  b.insert(b.end(), {0xFF, 0xC0});
  put_be(b, 17, 2);
  b.push_back(8);
  put_be(b, h, 2);
  put_be(b, w, 2);
  b.insert(b.end(), {3, 1, 0x11, 0, 2, 0x11, 1, 3, 0x11, 1, 0xFF, 0xD9});
  return b;
}

}  // namespace

TEST_CASE("load_image says what a path is that is no image file, before reading it", "[image_io][hostile]") {
  const std::string dir = temp_dir();
  const std::string fifo = dir + "/pipe.png";
  std::remove(fifo.c_str());
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  kage::ImageResult r = kage::load_image(fifo, 3);  // opened without blocking: no writer, no hang
  CHECK(r.kind == kage::ImageError::kUnreadable);
  CHECK(r.error == fifo + ": is not a regular file (a FIFO, device or socket); name an image file");
  r = kage::load_image("/dev/zero", 3);
  CHECK(r.error == "/dev/zero: is not a regular file (a FIFO, device or socket); name an image file");
  r = kage::load_image(dir, 3);
  CHECK(r.kind == kage::ImageError::kUnreadable);
  CHECK(r.error == dir + ": is a directory, not an image file; name an image file");
  std::remove(fifo.c_str());

  const std::string big = dir + "/big.png";
  write_bytes(big, png_claiming(64, 64));
  fs::resize_file(big, uint64_t(1) << 30);  // sparse
  const uint64_t rss = peak_rss_bytes();
  r = kage::load_image(big, 3);
  CHECK(r.kind == kage::ImageError::kTooLarge);
  CHECK(r.error == big + ": is 1073741824 bytes, more than an image file may be (256 MiB); use a smaller image");
  CHECK(peak_rss_bytes() < rss + (uint64_t(256) << 20));  // not read
  fs::remove(big);
}

TEST_CASE("a header claiming a huge image is too large, in every format", "[image_io][hostile]") {
  struct Case {
    const char* name;
    std::vector<uint8_t> bytes;
    const char* says;
  };
  const Case cases[] = {
      {"png", png_claiming(50000, 50000), "image too large: 50000x50000 pixels"},
      {"png_wide", png_claiming(1u << 31, 1), "image too large: 2147483648x1 pixels"},
      {"bmp", bmp_claiming(30000, 30000), "image too large: 30000x30000 pixels"},
      {"gif", gif_claiming(65535, 65535), "image too large: 65535x65535 pixels"},
      {"jpeg", jpeg_claiming(60000, 60000), "image too large: 60000x60000 pixels"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const std::string path = temp_dir() + "/claims_" + c.name;
    write_bytes(path, c.bytes);
    const kage::ImageResult r = kage::load_image(path, 3);
    CHECK(r.kind == kage::ImageError::kTooLarge);
    CHECK(r.error == path + ": " + c.says + ", more than 16777216 (4096x4096); use a smaller image");
  }
  // 4096 x 4096 is allowed: the header check passes it on to the decoder.
  const std::string ok = temp_dir() + "/claims_ok.png";
  write_bytes(ok, png_claiming(4096, 4096));
  CHECK(kage::load_image(ok, 3).kind == kage::ImageError::kCorrupt);
}
