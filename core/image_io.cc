#include "core/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory_budget.h"

namespace core {
namespace fs = std::filesystem;

namespace {

template <typename T>
OIIO::TypeDesc TypeOf();
template <>
OIIO::TypeDesc TypeOf<uint8_t>() {
  return OIIO::TypeDesc::UINT8;
}
template <>
OIIO::TypeDesc TypeOf<uint16_t>() {
  return OIIO::TypeDesc::UINT16;
}
template <>
OIIO::TypeDesc TypeOf<float>() {
  return OIIO::TypeDesc::FLOAT;
}

// OIIO's format name for the file's extension ("" = any format accepted).
std::string ExpectedFormat(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return "png";
  if (ext == ".jpg" || ext == ".jpeg") return "jpeg";
  if (ext == ".exr") return "openexr";
  if (ext == ".tif" || ext == ".tiff") return "tiff";
  return "";
}

// A JPEG ends with the EOI marker (FF D9); libjpeg fills a truncated file's
// missing rows with grey and only warns, so the check is ours.
bool JpegHasEndMarker(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  if (size < 4) return false;
  // Some writers pad after EOI: look at the last 64 bytes.
  const std::streamoff tail = std::min<std::streamoff>(size, 64);
  std::string bytes(static_cast<size_t>(tail), '\0');
  in.seekg(size - tail);
  in.read(bytes.data(), tail);
  return bytes.find("\xFF\xD9") != std::string::npos;
}

// Walks a PNG's chunks (length, type, data, CRC-32) up to IEND: "" if the
// file is whole, else what is wrong. libpng itself would print its own
// "libpng error" lines on such files before OIIO reports them.
std::string PngStructureProblem(const fs::path& path) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 8 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n", 8) != 0)
    return "no PNG signature";
  auto be32 = [&](size_t at) {
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  for (size_t at = 8;;) {
    if (bytes.size() - at < 12) return "truncated PNG (no IEND chunk)";
    const uint64_t length = be32(at);
    const std::string type = bytes.substr(at + 4, 4);
    if (length > bytes.size() - at - 12)
      return fmt::format("truncated PNG (ends inside chunk {})", type);
    uint32_t crc = 0xffffffffu;
    for (size_t i = at + 4; i < at + 8 + length; ++i) {
      crc = table[(crc ^ static_cast<unsigned char>(bytes[i])) & 0xff] ^ (crc >> 8);
    }
    if ((crc ^ 0xffffffffu) != be32(at + 8 + length))
      return fmt::format("corrupt PNG (chunk {} fails its CRC)", type);
    if (type == "IEND") return "";
    at += 12 + length;
  }
}

std::unique_ptr<OIIO::ImageInput> OpenInput(const fs::path& path, std::string_view where) {
  if (!fs::exists(path)) ThrowFileError(where, path, "file does not exist");
  if (!fs::is_regular_file(path)) ThrowFileError(where, path, "not a regular file");
  // Keep alpha as stored (no premultiplication): pixel values round-trip exactly.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto input = OIIO::ImageInput::open(path.string(), &config);
  if (!input) {
    std::string message = OIIO::geterror();
    std::replace(message.begin(), message.end(), '\n', ' ');
    ThrowFileError(where, path, "cannot decode image: {}", message);
  }
  const std::string expected = ExpectedFormat(path);
  if (!expected.empty() && expected != input->format_name()) {
    ThrowFileError(where, path, "is a {} file, not the {} its name says", input->format_name(),
                   expected);
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1) {
    ThrowFileError(where, path, "empty or volumetric image ({}x{}x{}, {} channels)", spec.width,
                   spec.height, spec.depth, spec.nchannels);
  }
  if (spec.width > kMaxImageSide || spec.height > kMaxImageSide ||
      spec.nchannels > kMaxImageChannels) {
    ThrowFileError(where, path,
                   "image is {}x{} with {} channels; the limit is {} pixels a side and {} channels",
                   spec.width, spec.height, spec.nchannels, kMaxImageSide, kMaxImageChannels);
  }
  // The decoded pixels in the file's type and in the caller's (up to 4-byte
  // floats) at once: checked before any is decoded, so a header claiming a
  // huge image is refused by the budget, not by the allocator.
  const uint64_t values = uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(spec.nchannels);
  CheckMemory(values * (spec.format.size() + sizeof(float)),
              fmt::format("{}: '{}'", where, path.string()),
              fmt::format("decoding a {}x{} image with {} channels", spec.width, spec.height,
                          spec.nchannels));
  if (expected == "png") {
    if (const std::string problem = PngStructureProblem(path); !problem.empty()) {
      ThrowFileError(where, path, "{}", problem);
    }
  }
  if (expected == "jpeg" && !JpegHasEndMarker(path)) {
    ThrowFileError(where, path, "truncated JPEG (no end-of-image marker)");
  }
  return input;
}

}  // namespace

ImageHeader ReadImageHeader(const fs::path& path) {
  auto input = OpenInput(path, "ReadImageHeader");
  const OIIO::ImageSpec& spec = input->spec();
  return {spec.width, spec.height, spec.nchannels};
}

template <typename T>
Image<T> ReadImage(const fs::path& path, int channels) {
  auto input = OpenInput(path, "ReadImage");
  const OIIO::ImageSpec& spec = input->spec();
  if (channels > 0 && spec.nchannels != channels) {
    ThrowFileError("ReadImage", path, "expected {} channel(s), file has {}", channels,
                   spec.nchannels);
  }
  Image<T> image(spec.width, spec.height, spec.nchannels);
  if (!input->read_image(0, 0, 0, spec.nchannels, TypeOf<T>(), image.data()) ||
      input->has_error()) {
    std::string message = input->geterror();
    std::replace(message.begin(), message.end(), '\n', ' ');
    ThrowFileError("ReadImage", path, "corrupt or truncated image data: {}", message);
  }
  input->close();
  return image;
}

template <typename T>
void WriteImage(const fs::path& path, const Image<T>& image) {
  if (image.empty()) ThrowFileError("WriteImage", path, "image is empty");
  AtomicWrite(path, [&](const fs::path& tmp) {
    // The temporary file keeps the real extension last so OIIO picks the format.
    const fs::path tmp_with_ext = fs::path(tmp.string() + path.extension().string());
    auto output = OIIO::ImageOutput::create(path.filename().string());
    if (!output) ThrowFileError("WriteImage", path, "unsupported format: {}", OIIO::geterror());
    OIIO::TypeDesc file_type = TypeOf<T>();
    const std::string ext = path.extension().string();
    const bool integer_format = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
    if (integer_format && file_type == OIIO::TypeDesc::FLOAT) file_type = OIIO::TypeDesc::UINT8;
    OIIO::ImageSpec spec(image.width(), image.height(), image.channels(), file_type);
    if (ext == ".exr") spec.attribute("compression", "zip");
    spec.attribute("oiio:UnassociatedAlpha", 1);  // our alpha is straight, not premultiplied
    spec.attribute("Software", kFileMark);
    if (!output->open(tmp_with_ext.string(), spec) ||
        !output->write_image(TypeOf<T>(), image.data()) || !output->close()) {
      std::error_code ignored;
      fs::remove(tmp_with_ext, ignored);
      ThrowFileError("WriteImage", path, "cannot write: {}", output->geterror());
    }
    fs::rename(tmp_with_ext, tmp);
  });
}

void MarkImageFile(const fs::path& file) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) ThrowFileError("MarkImageFile", file, "cannot read: {}", OIIO::geterror());
  OIIO::ImageSpec spec = in->spec();
  const std::string format = in->format_name();
  std::vector<unsigned char> pixels(spec.image_bytes());
  if (!in->read_image(0, 0, 0, spec.nchannels, spec.format, pixels.data())) {
    ThrowFileError("MarkImageFile", file, "cannot read: {}", in->geterror());
  }
  in->close();
  spec.attribute("Software", kFileMark);
  const fs::path marked = fs::path(file.string() + ".marked");
  auto output = OIIO::ImageOutput::create(format);
  if (!output || !output->open(marked.string(), spec) ||
      !output->write_image(spec.format, pixels.data()) || !output->close()) {
    std::error_code ignored;
    fs::remove(marked, ignored);
    ThrowFileError("MarkImageFile", file, "cannot write: {}",
                   output ? output->geterror() : OIIO::geterror());
  }
  fs::rename(marked, file);
}

template Image<uint8_t> ReadImage(const fs::path&, int);
template Image<uint16_t> ReadImage(const fs::path&, int);
template Image<float> ReadImage(const fs::path&, int);
template void WriteImage(const fs::path&, const Image<uint8_t>&);
template void WriteImage(const fs::path&, const Image<uint16_t>&);
template void WriteImage(const fs::path&, const Image<float>&);

}  // namespace core
