// Reading photos safely: the dimensions come from the file header, checked before OpenCV
// decodes anything (a forged 100k x 100k header would otherwise make it allocate tens of GB),
// and truncated files are refused instead of decoded half-grey (PNG: no IEND; JPEG: no end of
// image after the scan; BMP, TIFF: pixel data beyond the end of the file). An EXIF orientation
// tag is ignored: photos are read in the sensor's pixels (docs/methods/photos.md).

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "textile/photo/extract.h"
#include "textile/photo/image_codecs.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

struct Header {
  std::string format;  // "PNG", "JPEG", "TIFF", "BMP"
  int64_t width = 0, height = 0;
  bool complete = true;  // the end-of-image marker is present (PNG, JPEG)
};

uint32_t Be16(const uint8_t* p) { return (uint32_t(p[0]) << 8) | p[1]; }
uint32_t Be32(const uint8_t* p) { return (Be16(p) << 16) | Be16(p + 2); }
uint32_t Le16(const uint8_t* p) { return (uint32_t(p[1]) << 8) | p[0]; }
uint32_t Le32(const uint8_t* p) { return (Le16(p + 2) << 16) | Le16(p); }

bool StartsWith(const std::vector<uint8_t>& b, const char* magic, size_t n) {
  return b.size() >= n && std::memcmp(b.data(), magic, n) == 0;
}

bool ParsePng(const std::vector<uint8_t>& b, Header* h) {
  // Signature (8), then the IHDR chunk: length (4), "IHDR", width (4), height (4).
  if (b.size() < 24 || std::memcmp(b.data() + 12, "IHDR", 4) != 0) return false;
  h->format = "PNG";
  h->width = Be32(b.data() + 16);
  h->height = Be32(b.data() + 20);
  // The last chunk is IEND; a truncated file lacks it.
  const char* iend = "IEND";
  const auto from = b.end() - std::min<std::ptrdiff_t>(b.size() - 24, 4096);
  h->complete = std::search(from, b.end(), iend, iend + 4) != b.end();
  return true;
}

bool ParseJpeg(const std::vector<uint8_t>& b, Header* h) {
  h->format = "JPEG";
  size_t i = 2;
  while (i + 4 <= b.size()) {
    if (b[i] != 0xFF) return false;
    const uint8_t marker = b[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      i += 2;
      continue;
    }
    const uint32_t len = Be16(b.data() + i + 2);
    if (len < 2) return false;
    const bool sof =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (i + 9 > b.size()) return false;
      h->height = Be16(b.data() + i + 5);
      h->width = Be16(b.data() + i + 7);
    }
    if (marker == 0xDA) {  // start of scan: entropy-coded data follows
      // Inside the data every 0xFF is followed by 0x00 or a restart marker, so the first
      // FF D9 from here on is the end-of-image marker; a truncated file has none.
      h->complete = false;
      for (size_t k = i + 2 + len; k + 1 < b.size(); ++k) {
        if (b[k] == 0xFF && b[k + 1] == 0xD9) {
          h->complete = true;
          break;
        }
      }
      return h->width > 0 || h->height > 0;
    }
    i += 2 + len;
  }
  h->complete = false;  // ran out of data before the image data
  return h->width > 0 || h->height > 0;
}

bool ParseTiff(const std::vector<uint8_t>& b, Header* h) {
  if (b.size() < 8) return false;
  const bool le = b[0] == 'I';
  const auto u16 = [&](size_t o) { return le ? Le16(b.data() + o) : Be16(b.data() + o); };
  const auto u32 = [&](size_t o) { return le ? Le32(b.data() + o) : Be32(b.data() + o); };
  h->format = "TIFF";
  const size_t ifd = u32(4);
  if (ifd + 2 > b.size()) return false;
  const size_t n = u16(ifd);
  // Tag values: inline when they fit in 4 bytes, else at an offset. Returns false if cut off.
  const auto values = [&](size_t o, std::vector<uint64_t>* out) {
    const uint32_t type = u16(o + 2), count = u32(o + 4);
    const size_t size = type == 3 ? 2 : 4;
    if (count > (1u << 24)) return false;
    const size_t at = size * count <= 4 ? o + 8 : u32(o + 8);
    if (at + size * count > b.size()) return false;
    for (uint32_t k = 0; k < count; ++k)
      out->push_back(size == 2 ? u16(at + 2 * k) : u32(at + 4 * k));
    return true;
  };
  std::vector<uint64_t> offsets, counts;
  for (size_t e = 0; e < n; ++e) {
    const size_t o = ifd + 2 + 12 * e;
    if (o + 12 > b.size()) return false;
    const uint32_t tag = u16(o), type = u16(o + 2);
    const uint32_t value = type == 3 ? u16(o + 8) : u32(o + 8);
    if (tag == 256) h->width = value;
    if (tag == 257) h->height = value;
    // Strip or tile offsets and byte counts: all the image data must be in the file.
    if ((tag == 273 || tag == 324) && !values(o, &offsets)) return false;
    if ((tag == 279 || tag == 325) && !values(o, &counts)) return false;
  }
  h->complete = offsets.size() == counts.size();
  for (size_t k = 0; h->complete && k < offsets.size(); ++k) {
    h->complete = offsets[k] + counts[k] <= b.size();
  }
  return h->width > 0 && h->height > 0;
}

bool ParseBmp(const std::vector<uint8_t>& b, Header* h) {
  if (b.size() < 26) return false;
  h->format = "BMP";
  h->width = static_cast<int32_t>(Le32(b.data() + 18));
  h->height = static_cast<int32_t>(Le32(b.data() + 22));
  if (h->height < 0) h->height = -h->height;  // top-down bitmap
  // Uncompressed pixel rows (padded to 4 bytes) must all be in the file; otherwise the file
  // must be as long as its header says.
  if (b.size() >= 34 && Le32(b.data() + 30) == 0) {
    const uint64_t bits = Le16(b.data() + 28);
    const uint64_t row =
        (bits * static_cast<uint64_t>(std::max<int64_t>(h->width, 0)) + 31) / 32 * 4;
    h->complete = Le32(b.data() + 10) + row * static_cast<uint64_t>(h->height) <= b.size();
  } else {
    h->complete = Le32(b.data() + 2) <= b.size();
  }
  return true;
}

}  // namespace

cv::Mat ReadPhotoGray(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a folder, not a photo");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open photo");
  // One read of the whole file (a 50 MP photo is tens of MB: byte-wise stream iterators cost
  // more than a tenth of its decoding).
  std::vector<uint8_t> bytes;
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (file_size > 0) {
    bytes.resize(static_cast<size_t>(file_size));
    in.read(reinterpret_cast<char*>(bytes.data()), file_size);
    bytes.resize(static_cast<size_t>(in.gcount()));
  } else {  // not seekable (a pipe): read it as a stream
    in.clear();
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  if (in.bad()) throw InputError(path + ": cannot read photo");
  if (bytes.empty()) throw InputError(path + ": empty file, not an image");

  Header h;
  bool parsed = false;
  if (StartsWith(bytes, "\x89PNG\r\n\x1a\n", 8)) {
    parsed = ParsePng(bytes, &h);
  } else if (StartsWith(bytes, "\xFF\xD8\xFF", 3)) {
    parsed = ParseJpeg(bytes, &h);
  } else if (StartsWith(bytes, "II*\0", 4) || StartsWith(bytes, "MM\0*", 4)) {
    parsed = ParseTiff(bytes, &h);
  } else if (StartsWith(bytes, "BM", 2)) {
    parsed = ParseBmp(bytes, &h);
  } else {
    throw InputError(path + ": not a supported image (PNG, JPEG, TIFF or BMP expected)");
  }
  if (!parsed) throw InputError(path + ": damaged " + h.format + " header");
  std::ostringstream size;
  size << h.width << "x" << h.height << " px";
  if (h.width < kMinPhotoSidePx || h.height < kMinPhotoSidePx) {
    throw InputError(path + ": " + size.str() + " is too small for a cantilever photo (at least " +
                     std::to_string(kMinPhotoSidePx) + " px a side)");
  }
  if (h.width > kMaxPhotoSidePx || h.height > kMaxPhotoSidePx ||
      static_cast<double>(h.width) * static_cast<double>(h.height) > kMaxPhotoPixels) {
    throw InputError(path + ": the header says " + size.str() + ", more than the " +
                     std::to_string(static_cast<int>(kMaxPhotoPixels / 1e6)) +
                     " MP this tool accepts (damaged or forged header?)");
  }
  if (!h.complete)
    throw InputError(path + ": truncated " + h.format + " file (image data missing)");

  // The pixels as the sensor recorded them: an EXIF orientation tag (a camera held upright) is
  // ignored. Rigs and chessboards are calibrated in sensor pixels, and board and strip photos go
  // through here alike, so turning them would only break the rig's image_size and homography.
  cv::Mat gray;
  try {
    gray = image_codecs::Decode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()),
                                cv::IMREAD_GRAYSCALE | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot decode " + h.format + ": " + e.err);
  }
  if (gray.empty()) throw InputError(path + ": cannot decode " + h.format + " (damaged file?)");
  if (gray.cols != h.width || gray.rows != h.height) {
    throw InputError(path + ": decoded size differs from the header (damaged file?)");
  }
  return gray;
}

}  // namespace textile
