// Host image I/O over stb_image / stb_image_write, plus a bit-faithful port of
// Pillow's 8-bit Lanczos resampler (libImaging/Resample.c).
#include "fileio/image_io.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <fmt/format.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace kage {
namespace {

ImageResult fail(ImageError kind, const std::string& name, const std::string& reason) {
  ImageResult r;
  r.kind = kind;
  r.error = fmt::format("{}: {}", name, reason);
  return r;
}

enum class Format { kUnknown, kPng, kJpeg, kBmp, kGif };

Format sniff(const uint8_t* d, size_t n) {
  if (n >= 8 && std::memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0) return Format::kPng;
  if (n >= 3 && d[0] == 0xFF && d[1] == 0xD8 && d[2] == 0xFF) return Format::kJpeg;
  if (n >= 2 && d[0] == 'B' && d[1] == 'M') return Format::kBmp;
  if (n >= 6 && (std::memcmp(d, "GIF87a", 6) == 0 || std::memcmp(d, "GIF89a", 6) == 0)) return Format::kGif;
  return Format::kUnknown;
}

// stb decodes a JPEG cut short by filling the rest with zeros; Pillow refuses
// it ("image file is truncated"). Require an end-of-image marker after the
// first start-of-scan (scan data escapes 0xFF as FF 00, so FF D9 is a marker).
bool jpeg_has_eoi(const uint8_t* d, size_t n) {
  size_t i = 2;
  while (i + 1 < n && !(d[i] == 0xFF && d[i + 1] == 0xDA)) ++i;
  for (; i + 1 < n; ++i) {
    if (d[i] == 0xFF && d[i + 1] == 0xD9) return true;
  }
  return false;
}

// PNG: stb ignores a missing IEND; a file cut short loses it.
bool png_has_iend(const uint8_t* d, size_t n) {
  static const char kIend[] = "IEND";
  for (size_t i = n >= 12 ? n - 12 : 0; i + 4 <= n; ++i) {
    if (std::memcmp(d + i, kIend, 4) == 0) return true;
  }
  return false;
}

uint32_t be16(const uint8_t* p) { return uint32_t(p[0]) << 8 | p[1]; }
uint32_t be32(const uint8_t* p) { return be16(p) << 16 | be16(p + 2); }
uint32_t le16(const uint8_t* p) { return uint32_t(p[1]) << 8 | p[0]; }
uint32_t le32(const uint8_t* p) { return le16(p + 2) << 16 | le16(p); }

// Width and height as the header states them, read from the first bytes only: a file can claim a
// size that stb_image refuses with an unrelated reason ("unknown image type"), or that would take
// gigabytes to decode.
std::optional<std::pair<int64_t, int64_t>> header_dimensions(const uint8_t* d, size_t n) {
  switch (sniff(d, n)) {
    case Format::kPng:
      if (n >= 24 && std::memcmp(d + 12, "IHDR", 4) == 0) return std::make_pair(int64_t(be32(d + 16)), int64_t(be32(d + 20)));
      return std::nullopt;
    case Format::kGif:
      if (n >= 10) return std::make_pair(int64_t(le16(d + 6)), int64_t(le16(d + 8)));
      return std::nullopt;
    case Format::kBmp: {
      if (n < 26) return std::nullopt;
      if (le32(d + 14) == 12) return std::make_pair(int64_t(le16(d + 18)), int64_t(le16(d + 20)));
      const int64_t w = int32_t(le32(d + 18)), h = int32_t(le32(d + 22));  // a negative height is top-down
      return std::make_pair(w < 0 ? -w : w, h < 0 ? -h : h);
    }
    case Format::kJpeg:
      // Segments up to the first frame header (SOF0..SOF15 but DHT, JPG and DAC); none before the scan.
      for (size_t i = 2; i + 9 < n;) {
        if (d[i] != 0xFF) return std::nullopt;
        const uint8_t marker = d[i + 1];
        if (marker == 0xFF) {
          ++i;  // fill byte
          continue;
        }
        if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {
          i += 2;
          continue;
        }
        if (marker == 0xDA || marker == 0xD9) return std::nullopt;
        if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
          return std::make_pair(int64_t(be16(d + i + 7)), int64_t(be16(d + i + 5)));
        i += 2 + be16(d + i + 2);
      }
      return std::nullopt;
    case Format::kUnknown:
      break;
  }
  return std::nullopt;
}

std::string too_large_text(int64_t w, int64_t h) {
  return fmt::format("image too large: {}x{} pixels, more than {} ({}x{}); use a smaller image", w, h, kMaxImagePixels,
                     4096, 4096);
}

}  // namespace

std::optional<std::string> header_size_problem(const uint8_t* data, size_t size) {
  const auto dims = header_dimensions(data, size);
  if (!dims || dims->first * dims->second <= kMaxImagePixels) return std::nullopt;
  return too_large_text(dims->first, dims->second);
}

ImageFileBytes read_image_file(const std::string& path) {
  ImageFileBytes r;
  auto fail = [&](ImageError kind, std::string reason) {
    r.kind = kind;
    r.reason = std::move(reason);
    r.error = fmt::format("{}: {}", path, r.reason);
    return r;
  };
  // Opened without blocking, then checked: a FIFO or device is refused before a read could hang or
  // run without end, and a huge file before it is read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT || errno == ENOTDIR) return fail(ImageError::kMissing, "no such file; fix the path");
    return fail(ImageError::kUnreadable, fmt::format("cannot open ({})", std::strerror(errno)));
  }
  struct stat st {};
  std::string reason;
  ImageError kind = ImageError::kUnreadable;
  if (::fstat(fd, &st) != 0) {
    reason = fmt::format("cannot read its status ({})", std::strerror(errno));
  } else if (S_ISDIR(st.st_mode)) {
    r.not_a_file = true;
    reason = "is a directory, not an image file; name an image file";
  } else if (!S_ISREG(st.st_mode)) {
    r.not_a_file = true;
    reason = "is not a regular file (a FIFO, device or socket); name an image file";
  } else if (uint64_t(st.st_size) > kMaxImageFileBytes) {
    kind = ImageError::kTooLarge;
    reason = fmt::format("is {} bytes, more than an image file may be ({} MiB); use a smaller image",
                         uint64_t(st.st_size), kMaxImageFileBytes >> 20);
  } else {
    std::string bytes(size_t(st.st_size), '\0');
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t got = ::read(fd, bytes.data() + done, bytes.size() - done);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) break;
      done += size_t(got);
    }
    if (done == bytes.size()) {
      r.bytes = std::move(bytes);
    } else {
      reason = "read error (the file changed or could not be read); check it";
    }
  }
  ::close(fd);
  if (r.ok()) return r;
  return fail(kind, reason);
}

ImageResult decode_image(const uint8_t* data, size_t size, int channels, const std::string& name) {
  if (channels != 3 && channels != 4) {
    return fail(ImageError::kUnsupported, name, fmt::format("unsupported channel count {}", channels));
  }
  if (size == 0) return fail(ImageError::kEmpty, name, "empty file (0 bytes)");
  const Format format = sniff(data, size);
  if (format == Format::kUnknown) {
    return fail(ImageError::kUnsupported, name, "unsupported or corrupt image format (not PNG, JPEG, BMP or GIF)");
  }
  if (const std::optional<std::string> too_large = header_size_problem(data, size))
    return fail(ImageError::kTooLarge, name, *too_large);
  if (format == Format::kJpeg && !jpeg_has_eoi(data, size)) {
    return fail(ImageError::kCorrupt, name, "corrupt JPEG: truncated (no end-of-image marker)");
  }
  if (format == Format::kPng && !png_has_iend(data, size)) {
    return fail(ImageError::kCorrupt, name, "corrupt PNG: truncated (no IEND chunk)");
  }
  if (size > size_t(INT32_MAX)) return fail(ImageError::kUnsupported, name, "file too large");
  int w = 0, h = 0, n = 0;
  if (stbi_info_from_memory(data, int(size), &w, &h, &n) && int64_t(w) * int64_t(h) > kMaxImagePixels)
    return fail(ImageError::kTooLarge, name, too_large_text(w, h));
  stbi_uc* px = stbi_load_from_memory(data, int(size), &w, &h, &n, channels);
  if (px == nullptr) {
    const char* why = stbi_failure_reason();
    static const char* const kNames[] = {"", "PNG", "JPEG", "BMP", "GIF"};
    return fail(ImageError::kCorrupt, name,
                fmt::format("corrupt {} data ({})", kNames[int(format)], why ? why : "decode failed"));
  }
  if (w <= 0 || h <= 0) {
    stbi_image_free(px);
    return fail(ImageError::kEmpty, name, "image has zero size");
  }
  ImageResult r;
  Image img;
  img.width = w;
  img.height = h;
  img.channels = channels;
  img.pixels.assign(px, px + size_t(w) * h * channels);
  stbi_image_free(px);
  r.image = std::move(img);
  return r;
}

ImageResult load_image(const std::string& path, int channels) {
  const ImageFileBytes file = read_image_file(path);
  if (!file.ok()) {
    ImageResult r;
    r.kind = file.kind;
    r.error = file.error;
    return r;
  }
  return decode_image(reinterpret_cast<const uint8_t*>(file.bytes->data()), file.bytes->size(), channels, path);
}

namespace {

// stb's file writers ignore write and close errors: encode into memory, then write checked.
void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::string*>(context);
  out->append(static_cast<const char*>(data), static_cast<size_t>(size));
}

IoStatus write_bytes(const std::string& path, const std::string& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return {fmt::format("{}: cannot open for writing ({})", path, std::strerror(errno))};
  const bool wrote = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const bool closed = std::fclose(f) == 0;
  if (!wrote || !closed) return {fmt::format("{}: write failed ({})", path, std::strerror(errno))};
  return {};
}

}  // namespace

IoStatus write_png(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.channels < 1 || image.channels > 4 ||
      image.pixels.size() != size_t(image.width) * image.height * image.channels) {
    return {fmt::format("{}: invalid image for PNG output", path)};
  }
  std::string bytes;
  if (!stbi_write_png_to_func(append_bytes, &bytes, image.width, image.height, image.channels, image.pixels.data(),
                              image.width * image.channels)) {
    return {fmt::format("{}: cannot encode PNG", path)};
  }
  return write_bytes(path, bytes);
}

IoStatus write_jpeg(const std::string& path, const Image& image, int quality) {
  if (image.width <= 0 || image.height <= 0 || image.channels != 3 ||
      image.pixels.size() != size_t(image.width) * image.height * 3) {
    return {fmt::format("{}: invalid image for JPEG output (RGB required)", path)};
  }
  std::string bytes;
  if (!stbi_write_jpg_to_func(append_bytes, &bytes, image.width, image.height, 3, image.pixels.data(), quality)) {
    return {fmt::format("{}: cannot encode JPEG", path)};
  }
  return write_bytes(path, bytes);
}

// ---- Pillow Lanczos (libImaging/Resample.c, 8 bits per channel) ----
namespace {

constexpr int kPrecisionBits = 32 - 8 - 2;

double sinc(double x) {
  if (x == 0.0) return 1.0;
  x *= M_PI;
  return std::sin(x) / x;
}

double lanczos3(double x) { return (-3.0 <= x && x < 3.0) ? sinc(x) * sinc(x / 3) : 0.0; }

struct Coeffs {
  int ksize = 0;
  std::vector<int> bounds;     // per output: xmin, count
  std::vector<int32_t> k;      // per output: ksize fixed-point weights
};

Coeffs precompute(int in_size, int out_size) {
  const double in0 = 0.0, in1 = double(float(in_size));
  double filterscale = (in1 - in0) / out_size;
  const double scale = filterscale;
  if (filterscale < 1.0) filterscale = 1.0;
  const double support = 3.0 * filterscale;
  Coeffs c;
  c.ksize = int(std::ceil(support)) * 2 + 1;
  c.bounds.resize(size_t(out_size) * 2);
  std::vector<double> kk(size_t(out_size) * c.ksize, 0.0);
  for (int xx = 0; xx < out_size; ++xx) {
    const double center = in0 + (xx + 0.5) * scale;
    const double ss = 1.0 / filterscale;
    int xmin = int(center - support + 0.5);
    if (xmin < 0) xmin = 0;
    int xmax = int(center + support + 0.5);
    if (xmax > in_size) xmax = in_size;
    xmax -= xmin;
    double* k = &kk[size_t(xx) * c.ksize];
    double ww = 0.0;
    for (int x = 0; x < xmax; ++x) {
      const double w = lanczos3((x + xmin - center + 0.5) * ss);
      k[x] = w;
      ww += w;
    }
    for (int x = 0; x < xmax; ++x) {
      if (ww != 0.0) k[x] /= ww;
    }
    c.bounds[size_t(xx) * 2] = xmin;
    c.bounds[size_t(xx) * 2 + 1] = xmax;
  }
  c.k.resize(kk.size());
  for (size_t i = 0; i < kk.size(); ++i) {
    c.k[i] = kk[i] < 0 ? int32_t(-0.5 + kk[i] * (1 << kPrecisionBits))
                       : int32_t(0.5 + kk[i] * (1 << kPrecisionBits));
  }
  return c;
}

uint8_t clip8(int64_t in) {
  if (in >= (int64_t(1) << kPrecisionBits << 8)) return 255;
  if (in <= 0) return 0;
  return uint8_t(in >> kPrecisionBits);
}

}  // namespace

Image resize_lanczos(const Image& image, int width, int height) {
  const int nc = image.channels;
  Image cur = image;
  const bool need_h = width != image.width;
  const bool need_v = height != image.height;
  const Coeffs ch = precompute(image.width, width);
  Coeffs cv = precompute(image.height, height);
  const int ybox_first = cv.bounds[0];
  const int ybox_last = cv.bounds[size_t(height) * 2 - 2] + cv.bounds[size_t(height) * 2 - 1];
  if (need_h) {
    // Only the source rows the vertical pass reads are resampled.
    for (int i = 0; i < height; ++i) cv.bounds[size_t(i) * 2] -= ybox_first;
    Image tmp;
    tmp.width = width;
    tmp.height = ybox_last - ybox_first;
    tmp.channels = nc;
    tmp.pixels.resize(size_t(tmp.width) * tmp.height * nc);
    for (int y = 0; y < tmp.height; ++y) {
      for (int xx = 0; xx < width; ++xx) {
        const int xmin = ch.bounds[size_t(xx) * 2], xcount = ch.bounds[size_t(xx) * 2 + 1];
        const int32_t* k = &ch.k[size_t(xx) * ch.ksize];
        for (int c = 0; c < nc; ++c) {
          int64_t ss = int64_t(1) << (kPrecisionBits - 1);
          for (int x = 0; x < xcount; ++x) ss += int64_t(image.at(x + xmin, y + ybox_first)[c]) * k[x];
          tmp.at(xx, y)[c] = clip8(ss);
        }
      }
    }
    cur = std::move(tmp);
  }
  if (need_v) {
    Image out;
    out.width = cur.width;
    out.height = height;
    out.channels = nc;
    out.pixels.resize(size_t(out.width) * height * nc);
    for (int yy = 0; yy < height; ++yy) {
      const int ymin = cv.bounds[size_t(yy) * 2], ycount = cv.bounds[size_t(yy) * 2 + 1];
      const int32_t* k = &cv.k[size_t(yy) * cv.ksize];
      for (int x = 0; x < out.width; ++x) {
        for (int c = 0; c < nc; ++c) {
          int64_t ss = int64_t(1) << (kPrecisionBits - 1);
          for (int y = 0; y < ycount; ++y) ss += int64_t(cur.at(x, y + ymin)[c]) * k[y];
          out.at(x, yy)[c] = clip8(ss);
        }
      }
    }
    cur = std::move(out);
  }
  return cur;
}

}  // namespace kage
