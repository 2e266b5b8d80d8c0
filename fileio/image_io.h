// Host image I/O: decode PNG/JPEG/BMP files into 8-bit RGB or RGBA buffers,
// write PNG/JPEG, and resize with Pillow's Lanczos filter (spec 2.4 step 5).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace kage {

/// An 8-bit image, rows top to bottom, channels interleaved (RGB or RGBA),
/// `pixels.size() == width * height * channels`.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint8_t> pixels;

  /// Pointer to pixel (x, y), channel 0.
  const uint8_t* at(int x, int y) const { return pixels.data() + (size_t(y) * width + x) * channels; }
  uint8_t* at(int x, int y) { return pixels.data() + (size_t(y) * width + x) * channels; }
};

/// Why an image could not be loaded or written.
enum class ImageError {
  kNone,
  kMissing,      ///< the path does not exist
  kUnreadable,   ///< exists but cannot be opened or read (permissions, a directory)
  kEmpty,        ///< a zero-byte file, or a decoded size of zero
  kUnsupported,  ///< not a PNG, JPEG, BMP or GIF signature
  kCorrupt,      ///< right signature, but decoding failed or the data is truncated
  kTooLarge,     ///< decodes to more than kMaxImagePixels pixels
  kWriteFailed,  ///< an output file could not be written
};

/// Result of a load: `image` on success, else `kind` and a message that starts
/// with the file path ("path: reason").
struct [[nodiscard]] ImageResult {
  std::optional<Image> image;
  ImageError kind = ImageError::kNone;
  std::string error;
  bool ok() const { return image.has_value(); }
};

/// Result of a write: `error` empty on success, else "path: reason".
struct [[nodiscard]] IoStatus {
  std::string error;
  bool ok() const { return error.empty(); }
};

/// The most pixels an image may decode to (4096 x 4096): a small file can claim a huge size, and
/// decoding it would take seconds and gigabytes. Checked from the header, before decoding.
inline constexpr int64_t kMaxImagePixels = int64_t(4096) * 4096;

/// The largest image file read: a 4096 x 4096 RGBA BMP (the largest image kMaxImagePixels allows) is
/// 64 MiB, a PNG or JPEG of it less. A larger file is refused by its size before any byte is read.
inline constexpr uint64_t kMaxImageFileBytes = uint64_t(256) << 20;

/// An image file's bytes, or why they were not read: kMissing, kUnreadable (a directory, a FIFO or
/// device, an open or read error) or kTooLarge (more than kMaxImageFileBytes). `reason` says what the
/// path is and how to fix it; `error` is "path: reason".
struct [[nodiscard]] ImageFileBytes {
  std::optional<std::string> bytes;
  ImageError kind = ImageError::kNone;
  bool not_a_file = false;  ///< a directory, FIFO, device or socket (kUnreadable)
  std::string reason;
  std::string error;
  bool ok() const { return bytes.has_value(); }
};

/// Reads `path` after checking, without blocking, that it is a regular file of a readable size.
ImageFileBytes read_image_file(const std::string& path);

/// "image too large: WxH pixels, ..." when the header of a PNG, JPEG, BMP or GIF (the first bytes of
/// `data`) states more than kMaxImagePixels pixels; nullopt otherwise (no header found included).
std::optional<std::string> header_size_problem(const uint8_t* data, size_t size);

/// Loads `path` and converts it to `channels` (3 = RGB, 4 = RGBA) like Pillow's
/// `convert`: grey is replicated, alpha is dropped for RGB and set to 255 when
/// absent. PNG, JPEG and BMP (and the first frame of a GIF) are accepted.
ImageResult load_image(const std::string& path, int channels);

/// Same as load_image, from bytes already in memory; `name` prefixes errors.
ImageResult decode_image(const uint8_t* data, size_t size, int channels, const std::string& name);

/// Writes an RGB or RGBA image as PNG.
IoStatus write_png(const std::string& path, const Image& image);

/// Writes an RGB image as baseline JPEG with the given quality (1..100).
IoStatus write_jpeg(const std::string& path, const Image& image, int quality);

/// Resizes like Pillow's `Image.resize((w, h), Image.LANCZOS)` on an 8-bit
/// image: separable Lanczos-3, horizontal pass first, 22-bit fixed-point
/// coefficients; an axis whose size is unchanged is not resampled. RGB/grey
/// only (Pillow premultiplies RGBA, which this does not do). w, h >= 1.
Image resize_lanczos(const Image& image, int width, int height);

}  // namespace kage
