// GIF89a writer: global 256-entry colour table, NETSCAPE2.0 looping extension,
// one graphic control extension + image descriptor + LZW data per frame.
#include "runtime/io/gif_writer.h"

#include <fmt/format.h>

#include <cstdio>
#include <unordered_map>

namespace kage {
namespace {

constexpr int kLevelsR = 6, kLevelsG = 7, kLevelsB = 6;

int level_of(uint8_t v, int levels) { return (int(v) * (levels - 1) + 127) / 255; }
uint8_t value_of(int level, int levels) { return uint8_t((level * 255 + (levels - 1) / 2) / (levels - 1)); }

void put16(std::vector<uint8_t>& out, int v) {
  out.push_back(uint8_t(v & 0xFF));
  out.push_back(uint8_t((v >> 8) & 0xFF));
}

// Variable-width LZW with 8-bit minimum code size, codes packed LSB first,
// emitted as 255-byte sub-blocks. The dictionary resets when it reaches 4096.
class LzwEncoder {
 public:
  explicit LzwEncoder(std::vector<uint8_t>& out) : out_(out) {}

  void encode(const std::vector<uint8_t>& indices) {
    out_.push_back(kMinCodeSize);
    reset_dict();
    emit(kClear);
    int prefix = -1;
    for (uint8_t sym : indices) {
      if (prefix < 0) {
        prefix = sym;
        continue;
      }
      const uint32_t key = (uint32_t(prefix) << 8) | sym;
      auto it = dict_.find(key);
      if (it != dict_.end()) {
        prefix = it->second;
        continue;
      }
      emit(prefix);
      if (next_code_ < 4096) {
        dict_.emplace(key, next_code_);
        // The decoder widens one code later than the encoder adds the entry.
        if (next_code_ == (1 << code_size_) && code_size_ < 12) ++code_size_;
        ++next_code_;
      }
      if (next_code_ == 4096) {
        emit(kClear);
        reset_dict();
      }
      prefix = sym;
    }
    if (prefix >= 0) emit(prefix);
    emit(kEnd);
    flush_bits();
    flush_block();
    out_.push_back(0);  // block terminator
  }

 private:
  static constexpr int kMinCodeSize = 8;
  static constexpr int kClear = 256, kEnd = 257;

  void reset_dict() {
    dict_.clear();
    next_code_ = kEnd + 1;
    code_size_ = kMinCodeSize + 1;
  }
  void emit(int code) {
    bits_ |= uint32_t(code) << nbits_;
    nbits_ += code_size_;
    while (nbits_ >= 8) {
      push_byte(uint8_t(bits_ & 0xFF));
      bits_ >>= 8;
      nbits_ -= 8;
    }
  }
  void flush_bits() {
    if (nbits_ > 0) push_byte(uint8_t(bits_ & 0xFF));
    bits_ = 0;
    nbits_ = 0;
  }
  void push_byte(uint8_t b) {
    block_.push_back(b);
    if (block_.size() == 255) flush_block();
  }
  void flush_block() {
    if (block_.empty()) return;
    out_.push_back(uint8_t(block_.size()));
    out_.insert(out_.end(), block_.begin(), block_.end());
    block_.clear();
  }

  std::vector<uint8_t>& out_;
  std::vector<uint8_t> block_;
  std::unordered_map<uint32_t, int> dict_;
  int next_code_ = 0;
  int code_size_ = 0;
  uint32_t bits_ = 0;
  int nbits_ = 0;
};

}  // namespace

uint8_t gif_palette_index(uint8_t r, uint8_t g, uint8_t b) {
  return uint8_t((level_of(r, kLevelsR) * kLevelsG + level_of(g, kLevelsG)) * kLevelsB + level_of(b, kLevelsB));
}

void gif_palette_color(uint8_t index, uint8_t rgb[3]) {
  if (index >= kLevelsR * kLevelsG * kLevelsB) {
    rgb[0] = rgb[1] = rgb[2] = 0;
    return;
  }
  rgb[0] = value_of(index / (kLevelsG * kLevelsB), kLevelsR);
  rgb[1] = value_of((index / kLevelsB) % kLevelsG, kLevelsG);
  rgb[2] = value_of(index % kLevelsB, kLevelsB);
}

namespace {

int clamp_delay(int delay_cs) { return delay_cs < 0 ? 0 : delay_cs > 65535 ? 65535 : delay_cs; }

// Logical screen, global colour table and the looping extension.
void put_header(std::vector<uint8_t>& out, int w, int h) {
  for (char c : std::string("GIF89a")) out.push_back(uint8_t(c));
  put16(out, w);
  put16(out, h);
  out.push_back(0xF7);  // global colour table, 8 bits per primary, 256 entries
  out.push_back(0);     // background colour index
  out.push_back(0);     // pixel aspect ratio
  for (int i = 0; i < 256; ++i) {
    uint8_t rgb[3];
    gif_palette_color(uint8_t(i), rgb);
    out.insert(out.end(), rgb, rgb + 3);
  }
  // NETSCAPE2.0 application extension: loop count 0 = forever.
  const uint8_t kLoop[] = {0x21, 0xFF, 0x0B, 'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E',
                           '2',  '.',  '0',  0x03, 0x01, 0x00, 0x00, 0x00};
  out.insert(out.end(), kLoop, kLoop + sizeof(kLoop));
}

// One frame: graphic control extension, image descriptor, LZW data.
void put_frame(std::vector<uint8_t>& out, const Image& f, int delay_cs) {
  // Graphic control extension: no transparency, dispose "do not dispose".
  out.insert(out.end(), {0x21, 0xF9, 0x04, 0x04});
  put16(out, delay_cs);
  out.push_back(0);
  out.push_back(0);
  // Image descriptor: full frame, no local colour table, not interlaced.
  out.push_back(0x2C);
  put16(out, 0);
  put16(out, 0);
  put16(out, f.width);
  put16(out, f.height);
  out.push_back(0);
  std::vector<uint8_t> indices(size_t(f.width) * f.height);
  for (size_t p = 0; p < indices.size(); ++p) {
    const uint8_t* px = f.pixels.data() + p * f.channels;
    indices[p] = gif_palette_index(px[0], px[1], px[2]);
  }
  LzwEncoder(out).encode(indices);
}

bool valid_size(int w, int h) { return w > 0 && h > 0 && w <= 65535 && h <= 65535; }

bool matches(const Image& f, int w, int h) {
  return f.width == w && f.height == h && (f.channels == 3 || f.channels == 4) &&
         f.pixels.size() == size_t(w) * h * f.channels;
}

}  // namespace

std::vector<uint8_t> encode_gif(const std::vector<Image>& frames, int delay_cs, std::string* error) {
  std::vector<uint8_t> out;
  auto set_error = [&](const std::string& e) {
    if (error) *error = e;
    return std::vector<uint8_t>{};
  };
  if (frames.empty()) return set_error("no frames to encode");
  const int w = frames[0].width, h = frames[0].height;
  if (!valid_size(w, h)) return set_error("invalid frame size");
  for (size_t i = 0; i < frames.size(); ++i)
    if (!matches(frames[i], w, h)) return set_error(fmt::format("frame {} differs in size or is not RGB/RGBA", i));
  out.reserve(1024 + frames.size() * (size_t(w) * h + 64));
  put_header(out, w, h);
  for (const Image& f : frames) put_frame(out, f, clamp_delay(delay_cs));
  out.push_back(0x3B);  // trailer
  return out;
}

IoStatus write_gif(const std::string& path, const std::vector<Image>& frames, int delay_cs) {
  std::string error;
  const std::vector<uint8_t> bytes = encode_gif(frames, delay_cs, &error);
  if (bytes.empty()) return {fmt::format("{}: {}", path, error)};
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return {fmt::format("{}: cannot open for writing", path)};
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (std::fclose(f) != 0 || !ok) return {fmt::format("{}: write failed", path)};
  return {};
}

GifStream::~GifStream() {
  if (file_) std::fclose(file_);
}

IoStatus GifStream::open(const std::string& path, int width, int height, int delay_cs) {
  if (!valid_size(width, height)) return {fmt::format("{}: invalid frame size", path)};
  path_ = path;
  width_ = width;
  height_ = height;
  delay_cs_ = clamp_delay(delay_cs);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) return {fmt::format("{}: cannot open for writing", path)};
  std::vector<uint8_t> header;
  put_header(header, width, height);
  return put(header);
}

IoStatus GifStream::add(const Image& frame) {
  if (!file_) return {fmt::format("{}: not open", path_)};
  if (!matches(frame, width_, height_)) return {fmt::format("{}: frame differs in size or is not RGB/RGBA", path_)};
  std::vector<uint8_t> bytes;
  put_frame(bytes, frame, delay_cs_);
  return put(bytes);
}

IoStatus GifStream::finish() {
  if (!file_) return {fmt::format("{}: not open", path_)};
  const IoStatus st = put({0x3B});
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!st.ok()) return st;
  if (!closed) return {fmt::format("{}: write failed", path_)};
  return {};
}

IoStatus GifStream::put(const std::vector<uint8_t>& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    return {fmt::format("{}: write failed", path_)};
  return {};
}

}  // namespace kage
