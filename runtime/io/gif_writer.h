// Animated GIF89a encoder for `kagec render`: fixed 6x7x6 colour cube palette,
// LZW image data, per-frame delay, loops forever.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "fileio/image_io.h"

namespace kage {

/// Palette index of an RGB colour in the fixed palette: nearest level per
/// channel of a 6 (R) x 7 (G) x 6 (B) cube (252 colours, indices 0..251).
uint8_t gif_palette_index(uint8_t r, uint8_t g, uint8_t b);

/// The RGB colour of palette entry `index` (entries 252..255 are black).
void gif_palette_color(uint8_t index, uint8_t rgb[3]);

/// Encodes `frames` (all the same size, 3 or 4 channels; alpha is ignored) as
/// an animated GIF that loops forever, `delay_cs` hundredths of a second per
/// frame. Returns the file bytes, or an empty vector with `*error` set.
std::vector<uint8_t> encode_gif(const std::vector<Image>& frames, int delay_cs, std::string* error);

/// encode_gif, then writes the bytes to `path`.
IoStatus write_gif(const std::string& path, const std::vector<Image>& frames, int delay_cs);

/// The same GIF written one frame at a time, so that a long run never holds its frames in memory.
/// Every write and the close are checked.
class GifStream {
 public:
  GifStream() = default;
  GifStream(const GifStream&) = delete;
  GifStream& operator=(const GifStream&) = delete;
  ~GifStream();
  /// Creates `path` and writes the header for frames of width x height.
  IoStatus open(const std::string& path, int width, int height, int delay_cs);
  /// Appends one frame (3 or 4 channels, the size given to open).
  IoStatus add(const Image& frame);
  /// Writes the trailer and closes the file.
  IoStatus finish();

 private:
  IoStatus put(const std::vector<uint8_t>& bytes);
  std::string path_;
  int width_ = 0, height_ = 0, delay_cs_ = 0;
  std::FILE* file_ = nullptr;
};

}  // namespace kage
