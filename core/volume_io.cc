#include "core/volume_io.h"

#include <bzlib.h>
#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <map>
#include <memory>
#include <ostream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

// The official NIfTI-1/2 header layouts (nifticlib).
#include <nifti/nifti1.h>
#include <nifti/nifti2.h>

namespace core {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxHeaderLine = 4096;          // characters in one header line
constexpr size_t kMaxHeaderBytes = 65536;        // characters in a whole header
constexpr size_t kReadChunk = size_t{1} << 24;   // 16 MiB: largest step of a chunked read
constexpr size_t kFirstChunk = size_t{1} << 16;  // 64 KiB: the first step

// The next step of a read that has `have` of `total` bytes: doubling from
// kFirstChunk up to kReadChunk, so a short or compressed stream whose header
// claims a large volume allocates at most twice what it actually holds.
size_t NextChunk(size_t have, size_t total) {
  return std::min(total - have, std::clamp(have, kFirstChunk, kReadChunk));
}

std::string_view Trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

std::vector<std::string_view> SplitWords(std::string_view s) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    if (j > i) words.push_back(s.substr(i, j - i));
    i = j;
  }
  return words;
}

// One header line (without '\n'); false at end of stream with nothing read.
// Lines longer than kMaxHeaderLine and headers longer than kMaxHeaderBytes are
// refused: a binary file given as a header must not be read whole.
bool ReadHeaderLine(std::istream& in, std::string& line, size_t& header_bytes,
                    std::string_view where, std::string_view name) {
  line.clear();
  int c;
  bool any = false;
  while ((c = in.get()) != std::char_traits<char>::eof()) {
    any = true;
    if (++header_bytes > kMaxHeaderBytes) {
      ThrowFileError(where, name, "header longer than {} bytes (not a header?)", kMaxHeaderBytes);
    }
    if (c == '\n') return true;
    if (c == '\0') ThrowFileError(where, name, "NUL byte in the header (not a text header?)");
    if (line.size() >= kMaxHeaderLine)
      ThrowFileError(where, name, "header line longer than {}", kMaxHeaderLine);
    line.push_back(static_cast<char>(c));
  }
  return any;
}

int ParseInt(std::string_view word, std::string_view what, std::string_view where,
             std::string_view name) {
  int value = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec != std::errc() || end != word.data() + word.size()) {
    ThrowFileError(where, name, "{}: '{}' is not an integer", what, word);
  }
  return value;
}

double ParseDouble(std::string_view word, std::string_view what, std::string_view where,
                   std::string_view name) {
  double value = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (ec != std::errc() || end != word.data() + word.size()) {
    ThrowFileError(where, name, "{}: '{}' is not a number", what, word);
  }
  return value;
}

glm::ivec3 ParseDims(std::string_view value, std::string_view what, std::string_view where,
                     std::string_view name) {
  const auto words = SplitWords(value);
  if (words.size() != 3) ThrowFileError(where, name, "{}: expected 3 sizes, got '{}'", what, value);
  return {ParseInt(words[0], what, where, name), ParseInt(words[1], what, where, name),
          ParseInt(words[2], what, where, name)};
}

void CheckSpacing(const glm::dvec3& s, std::string_view where, std::string_view name) {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(s[a]) || s[a] <= 0 || s[a] > 1e12) {
      ThrowFileError(where, name, "spacing {} {} {}: each must be finite and > 0", s.x, s.y, s.z);
    }
  }
}

// Remaining bytes of a seekable stream; -1 when it cannot tell.
std::streamoff RemainingBytes(std::istream& in) {
  const auto here = in.tellg();
  if (here < 0) return -1;
  in.seekg(0, std::ios::end);
  const auto end = in.tellg();
  in.seekg(here);
  if (end < 0 || !in) {
    in.clear();
    in.seekg(here);
    return -1;
  }
  return end - here;
}

// Exactly `expected` bytes from `in`; an error naming the shortfall otherwise.
// When `exact`, bytes after them are an error too. Never allocates more than
// the bytes present plus one chunk.
std::vector<uint8_t> ReadExactly(std::istream& in, size_t expected, bool exact,
                                 std::string_view where, std::string_view name) {
  const std::streamoff remaining = RemainingBytes(in);
  if (remaining >= 0) {
    if (static_cast<size_t>(remaining) < expected) {
      ThrowFileError(where, name, "short data: {} bytes, the header says {}", remaining, expected);
    }
    if (exact && static_cast<size_t>(remaining) > expected) {
      ThrowFileError(where, name, "{} bytes of data, the header says {}", remaining, expected);
    }
  }
  std::vector<uint8_t> out;
  if (remaining >= 0) out.reserve(expected);
  while (out.size() < expected) {
    const size_t old = out.size();
    const size_t n = NextChunk(old, expected);
    out.resize(old + n);
    in.read(reinterpret_cast<char*>(out.data() + old), static_cast<std::streamsize>(n));
    const auto got = static_cast<size_t>(in.gcount());
    if (got < n)
      ThrowFileError(where, name, "short data: {} bytes, the header says {}", old + got, expected);
  }
  if (exact && in.peek() != std::char_traits<char>::eof()) {
    ThrowFileError(where, name, "more data than the {} bytes the header says", expected);
  }
  return out;
}

void SwapBytes(std::vector<uint8_t>& bytes, int width) {
  if (width == 1) return;
  for (size_t i = 0; i + width <= bytes.size(); i += width) {
    std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(i),
                 bytes.begin() + static_cast<std::ptrdiff_t>(i + width));
  }
}

std::ifstream OpenBinary(const fs::path& path, std::string_view where) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) ThrowFileError(where, path, "no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowFileError(where, path, "cannot open");
  return in;
}

// ---- decoders: raw, gzip (zlib), bzip2 (libbz2) ----

// A source of decoded data bytes.
class Decoder {
 public:
  virtual ~Decoder() = default;
  // Up to n decoded bytes into out; fewer only at the end of the data.
  // Corrupt or truncated compressed data: InputError.
  virtual size_t Read(uint8_t* out, size_t n) = 0;
};

class RawDecoder final : public Decoder {
 public:
  explicit RawDecoder(std::istream& in) : in_(in) {}
  size_t Read(uint8_t* out, size_t n) override {
    in_.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n));
    return static_cast<size_t>(in_.gcount());
  }

 private:
  std::istream& in_;
};

// The compressed input, read in blocks.
class InputBlocks {
 public:
  explicit InputBlocks(std::istream& in) : in_(in), block_(size_t{1} << 16) {}
  // Refills when the previous block is used up; false at the end of input.
  bool Next(const char*& data, size_t& size) {
    in_.read(block_.data(), static_cast<std::streamsize>(block_.size()));
    size = static_cast<size_t>(in_.gcount());
    data = block_.data();
    return size > 0;
  }

 private:
  std::istream& in_;
  std::vector<char> block_;
};

class GzipDecoder final : public Decoder {
 public:
  GzipDecoder(std::istream& in, std::string_view where, std::string_view name)
      : input_(in), where_(where), name_(name) {
    // 15 + 32: a zlib or gzip header, detected automatically.
    if (inflateInit2(&z_, 15 + 32) != Z_OK) ThrowFileError(where_, name_, "zlib: init failed");
  }
  ~GzipDecoder() override { inflateEnd(&z_); }
  size_t Read(uint8_t* out, size_t n) override {
    size_t produced = 0;
    while (produced < n && !ended_) {
      if (z_.avail_in == 0 && !input_done_) {
        const char* data;
        size_t size;
        input_done_ = !input_.Next(data, size);
        z_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
        z_.avail_in = static_cast<uInt>(size);
      }
      const auto room = static_cast<uInt>(std::min<size_t>(n - produced, size_t{1} << 30));
      z_.next_out = out + produced;
      z_.avail_out = room;
      const int status = inflate(&z_, Z_NO_FLUSH);
      produced += room - z_.avail_out;
      if (status == Z_STREAM_END) {
        ended_ = true;
      } else if (status == Z_BUF_ERROR || (status == Z_OK && room == z_.avail_out)) {
        if (input_done_ && z_.avail_in == 0)
          ThrowFileError(where_, name_, "truncated gzip data (ends before its end marker)");
      } else if (status != Z_OK) {
        ThrowFileError(where_, name_, "corrupt gzip data ({})", z_.msg ? z_.msg : "zlib error");
      }
    }
    return produced;
  }

 private:
  InputBlocks input_;
  z_stream z_{};
  bool input_done_ = false, ended_ = false;
  std::string where_, name_;
};

class Bzip2Decoder final : public Decoder {
 public:
  Bzip2Decoder(std::istream& in, std::string_view where, std::string_view name)
      : input_(in), where_(where), name_(name) {
    if (BZ2_bzDecompressInit(&b_, 0, 0) != BZ_OK)
      ThrowFileError(where_, name_, "bzip2: init failed");
  }
  ~Bzip2Decoder() override { BZ2_bzDecompressEnd(&b_); }
  size_t Read(uint8_t* out, size_t n) override {
    size_t produced = 0;
    while (produced < n && !ended_) {
      if (b_.avail_in == 0 && !input_done_) {
        const char* data;
        size_t size;
        input_done_ = !input_.Next(data, size);
        b_.next_in = const_cast<char*>(data);
        b_.avail_in = static_cast<unsigned>(size);
      }
      const auto room = static_cast<unsigned>(std::min<size_t>(n - produced, size_t{1} << 30));
      b_.next_out = reinterpret_cast<char*>(out + produced);
      b_.avail_out = room;
      const int status = BZ2_bzDecompress(&b_);
      produced += room - b_.avail_out;
      if (status == BZ_STREAM_END) {
        ended_ = true;
      } else if (status != BZ_OK) {
        ThrowFileError(where_, name_, "corrupt bzip2 data (libbz2 error {})", status);
      } else if (room == b_.avail_out && input_done_ && b_.avail_in == 0) {
        ThrowFileError(where_, name_, "truncated bzip2 data (ends before its end marker)");
      }
    }
    return produced;
  }

 private:
  InputBlocks input_;
  bz_stream b_{};
  bool input_done_ = false, ended_ = false;
  std::string where_, name_;
};

// `count` decoded bytes after `byte_skip` decoded bytes (-1: the last `count`
// bytes of the data); more data after them is an error. Allocates no more
// than the bytes actually decoded plus one chunk (twice `count` for -1).
std::vector<uint8_t> ReadDecoded(Decoder& d, size_t count, int64_t byte_skip,
                                 std::string_view where, std::string_view name) {
  std::vector<uint8_t> out;
  if (byte_skip >= 0) {
    std::vector<uint8_t> scratch(static_cast<size_t>(
        std::min<int64_t>(std::max<int64_t>(byte_skip, 1), static_cast<int64_t>(kFirstChunk))));
    for (int64_t left = byte_skip; left > 0;) {
      const size_t n = d.Read(scratch.data(), static_cast<size_t>(std::min<int64_t>(
                                                  left, static_cast<int64_t>(scratch.size()))));
      if (n == 0)
        ThrowFileError(where, name, "byte skip {} is past the end of the data", byte_skip);
      left -= static_cast<int64_t>(n);
    }
    while (out.size() < count) {
      const size_t old = out.size();
      const size_t n = NextChunk(old, count);
      out.resize(old + n);
      const size_t got = d.Read(out.data() + old, n);
      if (got < n)
        ThrowFileError(where, name, "short data: {} bytes, the header says {}", old + got, count);
    }
    uint8_t probe;
    if (d.Read(&probe, 1) != 0)
      ThrowFileError(where, name, "more data than the {} bytes the header says", count);
    return out;
  }
  // byte skip -1: keep a window of the last bytes decoded.
  size_t total = 0;
  for (;;) {
    const size_t old = out.size();
    const size_t step = std::clamp(old, kFirstChunk, kReadChunk);
    out.resize(old + step);
    const size_t got = d.Read(out.data() + old, step);
    out.resize(old + got);
    total += got;
    if (got < step) break;
    if (out.size() > 2 * count + kReadChunk)
      out.erase(out.begin(), out.end() - static_cast<std::ptrdiff_t>(count));
  }
  if (out.size() < count)
    ThrowFileError(where, name, "short data: {} bytes, the header says {}", total, count);
  out.erase(out.begin(), out.end() - static_cast<std::ptrdiff_t>(count));
  return out;
}

void Gzip(std::ostream& out, const std::vector<uint8_t>& data) {
  z_stream z{};
  // 15 + 16: a gzip header; level 6 is zlib's default trade-off.
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    ThrowInputError("WriteNrrd", "zlib: deflateInit2 failed");
  }
  std::vector<uint8_t> buffer(size_t{1} << 16);
  size_t offset = 0;
  int status = Z_OK;
  while (status != Z_STREAM_END) {
    const size_t n = std::min<size_t>(data.size() - offset, size_t{1} << 30);
    z.next_in = const_cast<Bytef*>(data.data() + offset);
    z.avail_in = static_cast<uInt>(n);
    const bool last = offset + n == data.size();
    do {
      z.next_out = buffer.data();
      z.avail_out = static_cast<uInt>(buffer.size());
      status = deflate(&z, last ? Z_FINISH : Z_NO_FLUSH);
      out.write(reinterpret_cast<const char*>(buffer.data()),
                static_cast<std::streamsize>(buffer.size() - z.avail_out));
    } while (z.avail_out == 0);
    offset += n;
  }
  deflateEnd(&z);
}

// ---- QVis ----

std::string_view QVisFormatName(ScalarType type) {
  switch (type) {
    case ScalarType::kUint8:
      return "UCHAR";
    case ScalarType::kUint16:
      return "USHORT";
    case ScalarType::kFloat32:
      return "FLOAT";
    default:
      ThrowInputError("WriteQVis", "QVis holds uint8, uint16 or float32, not {} (write NRRD)",
                      ScalarTypeName(type));
  }
}

std::string_view NrrdTypeName(ScalarType type) {
  switch (type) {
    case ScalarType::kFloat32:
      return "float";
    case ScalarType::kFloat64:
      return "double";
    default:
      return ScalarTypeName(type);  // uint8, int16, ...: NRRD's own names
  }
}

// ---- NRRD ----

enum class Encoding { kRaw, kGzip, kBzip2 };

ScalarType ParseNrrdType(std::string_view value, std::string_view where, std::string_view name) {
  // The type names of the NRRD specification (NRRD0005, "type:").
  static const std::map<std::string_view, ScalarType> kTypes = {
      {"signed char", ScalarType::kInt8},
      {"int8", ScalarType::kInt8},
      {"int8_t", ScalarType::kInt8},
      {"uchar", ScalarType::kUint8},
      {"unsigned char", ScalarType::kUint8},
      {"uint8", ScalarType::kUint8},
      {"uint8_t", ScalarType::kUint8},
      {"short", ScalarType::kInt16},
      {"short int", ScalarType::kInt16},
      {"signed short", ScalarType::kInt16},
      {"signed short int", ScalarType::kInt16},
      {"int16", ScalarType::kInt16},
      {"int16_t", ScalarType::kInt16},
      {"ushort", ScalarType::kUint16},
      {"unsigned short", ScalarType::kUint16},
      {"unsigned short int", ScalarType::kUint16},
      {"uint16", ScalarType::kUint16},
      {"uint16_t", ScalarType::kUint16},
      {"int", ScalarType::kInt32},
      {"signed int", ScalarType::kInt32},
      {"int32", ScalarType::kInt32},
      {"int32_t", ScalarType::kInt32},
      {"uint", ScalarType::kUint32},
      {"unsigned int", ScalarType::kUint32},
      {"uint32", ScalarType::kUint32},
      {"uint32_t", ScalarType::kUint32},
      {"float", ScalarType::kFloat32},
      {"double", ScalarType::kFloat64}};
  const auto it = kTypes.find(value);
  if (it == kTypes.end()) {
    ThrowFileError(where, name,
                   "type '{}' is not supported ((u)int8/16/32, float or double; 64-bit integers "
                   "and 'block' are not)",
                   value);
  }
  return it->second;
}

// "(x,y,z)" -> its length; "none" -> 0.
double ParseDirectionLength(std::string_view word, std::string_view where, std::string_view name) {
  if (word == "none") return 0;
  if (word.size() < 2 || word.front() != '(' || word.back() != ')') {
    ThrowFileError(where, name, "space directions: '{}' is not a vector '(x,y,z)'", word);
  }
  const std::string_view inner = word.substr(1, word.size() - 2);
  double sum = 0;
  size_t start = 0;
  int count = 0;
  while (start <= inner.size()) {
    const size_t comma = std::min(inner.find(',', start), inner.size());
    const double v =
        ParseDouble(Trim(inner.substr(start, comma - start)), "space directions", where, name);
    sum += v * v;
    ++count;
    start = comma + 1;
  }
  if (count < 1 || count > 3)
    ThrowFileError(where, name, "space directions: '{}' has {} components", word, count);
  return std::sqrt(sum);
}

// At most this many detached data files (one per slice of the largest
// accepted extent).
constexpr int64_t kMaxDataFiles = kMaxVolumeExtent;

// "slice%03d.raw" with one integer: the %d conversion with optional flags
// and width; "%%" is a literal percent. Anything else is refused.
std::string FormatDataFileName(std::string_view pattern, int64_t index, std::string_view where,
                               std::string_view name) {
  std::string out;
  int conversions = 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') {
      out.push_back(pattern[i]);
      continue;
    }
    if (i + 1 < pattern.size() && pattern[i + 1] == '%') {
      out.push_back('%');
      ++i;
      continue;
    }
    size_t j = i + 1;
    bool zero = false;
    while (j < pattern.size() &&
           (pattern[j] == '0' || pattern[j] == '-' || pattern[j] == '+' || pattern[j] == ' ')) {
      zero |= pattern[j] == '0';
      ++j;
    }
    int width = 0;
    while (j < pattern.size() && pattern[j] >= '0' && pattern[j] <= '9' && width < 100)
      width = width * 10 + (pattern[j++] - '0');
    if (j >= pattern.size() || (pattern[j] != 'd' && pattern[j] != 'i' && pattern[j] != 'u') ||
        ++conversions > 1) {
      ThrowFileError(where, name, "data file pattern '{}': expected one %d conversion", pattern);
    }
    out += zero ? fmt::format("{:0{}d}", index, width) : fmt::format("{:{}d}", index, width);
    i = j;
  }
  if (conversions != 1)
    ThrowFileError(where, name, "data file pattern '{}': expected one %d conversion", pattern);
  return out;
}

struct NrrdHeader {
  glm::ivec3 dims{0};
  glm::dvec3 spacing{1.0};
  ScalarType type = ScalarType::kUint8;
  Encoding encoding = Encoding::kRaw;
  bool big_endian = false;
  int64_t line_skip = 0;  // lines of each data file skipped before decoding
  int64_t byte_skip = 0;  // decoded bytes skipped after them; -1: the data ends the file
  // Detached data, in order (names relative to the header); empty when
  // attached.
  std::vector<std::string> data_files;
  int subdim = 0;  // dimension of each data file's part; 0: 3 for one file, 2 for several
};

NrrdHeader ReadNrrdHeader(std::istream& in, std::string_view name) {
  constexpr std::string_view where = "ReadNrrd";
  size_t header_bytes = 0;
  std::string line;
  if (!ReadHeaderLine(in, line, header_bytes, where, name))
    ThrowFileError(where, name, "empty file");
  const std::string_view magic = Trim(line);
  if (magic.size() != 8 || magic.substr(0, 7) != "NRRD000" || magic[7] < '1' || magic[7] > '5') {
    ThrowFileError(where, name, "not a NRRD file (first line '{}', expected NRRD0001..NRRD0005)",
                   magic.substr(0, 32));
  }
  NrrdHeader h;
  bool have_type = false, have_dimension = false, have_sizes = false, have_encoding = false;
  bool have_spacings = false, list = false;
  while (ReadHeaderLine(in, line, header_bytes, where, name)) {
    std::string_view l = line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    if (list) {
      // "data file: LIST": every further line names one data file.
      if (l.empty()) break;
      if (static_cast<int64_t>(h.data_files.size()) >= kMaxDataFiles)
        ThrowFileError(where, name, "more than {} data files", kMaxDataFiles);
      h.data_files.emplace_back(Trim(l));
      continue;
    }
    if (l.empty()) break;  // end of header; attached data follows
    if (l.front() == '#') continue;
    if (l.find(":=") != std::string_view::npos && l.find(":=") < l.find(": "))
      continue;  // key/value pair
    const size_t colon = l.find(": ");
    if (colon == std::string_view::npos)
      ThrowFileError(where, name, "header line '{}' is not 'field: value'", l.substr(0, 64));
    const std::string_view field = l.substr(0, colon);
    const std::string_view value = Trim(l.substr(colon + 2));
    if (field == "type") {
      h.type = ParseNrrdType(value, where, name);
      have_type = true;
    } else if (field == "dimension") {
      const int d = ParseInt(value, "dimension", where, name);
      if (d != 3) ThrowFileError(where, name, "dimension {} (only 3D volumes are read)", d);
      have_dimension = true;
    } else if (field == "sizes") {
      h.dims = ParseDims(value, "sizes", where, name);
      have_sizes = true;
    } else if (field == "encoding") {
      if (value == "raw") {
        h.encoding = Encoding::kRaw;
      } else if (value == "gzip" || value == "gz") {
        h.encoding = Encoding::kGzip;
      } else if (value == "bzip2" || value == "bz2") {
        h.encoding = Encoding::kBzip2;
      } else {
        ThrowFileError(where, name, "encoding '{}' is not supported (raw, gzip or bzip2)", value);
      }
      have_encoding = true;
    } else if (field == "endian") {
      if (value == "little") {
        h.big_endian = false;
      } else if (value == "big") {
        h.big_endian = true;
      } else {
        ThrowFileError(where, name, "endian '{}' (little or big)", value);
      }
    } else if (field == "spacings") {
      const auto words = SplitWords(value);
      if (words.size() != 3)
        ThrowFileError(where, name, "spacings: expected 3 values, got '{}'", value);
      for (int a = 0; a < 3; ++a) {
        // "nan" means unknown in NRRD: unit spacing.
        h.spacing[a] = words[a] == "nan" || words[a] == "NaN"
                           ? 1.0
                           : ParseDouble(words[a], "spacings", where, name);
      }
      have_spacings = true;
    } else if (field == "space directions") {
      // The voxel's edge vectors: their lengths are the spacings (the
      // orientation in patient space is not kept: the box is rendered
      // axis-aligned at its true size).
      const auto words = SplitWords(value);
      if (words.size() != 3)
        ThrowFileError(where, name, "space directions: expected 3 vectors, got '{}'", value);
      if (!have_spacings) {
        for (int a = 0; a < 3; ++a) {
          const double length = ParseDirectionLength(words[a], where, name);
          h.spacing[a] = length > 0 ? length : 1.0;
        }
      }
    } else if (field == "data file" || field == "datafile") {
      const auto words = SplitWords(value);
      if (words.empty()) ThrowFileError(where, name, "data file: no file named");
      if (words[0] == "LIST") {
        // "LIST [subdim]": the file names are the remaining header lines.
        if (words.size() > 2) ThrowFileError(where, name, "data file: '{}' after LIST", value);
        if (words.size() == 2) h.subdim = ParseInt(words[1], "data file subdim", where, name);
        list = true;
      } else if (words.size() == 1) {
        h.data_files.emplace_back(words[0]);
      } else if (words.size() == 4 || words.size() == 5) {
        // "FORMAT MIN MAX STEP [subdim]": the files FORMAT % i for i = MIN,
        // MIN + STEP, ... up to MAX.
        const int64_t min = ParseInt(words[1], "data file min", where, name);
        const int64_t max = ParseInt(words[2], "data file max", where, name);
        const int64_t step = ParseInt(words[3], "data file step", where, name);
        if (words.size() == 5) h.subdim = ParseInt(words[4], "data file subdim", where, name);
        if (step == 0 || (max - min) / step < 0 || (max - min) % step != 0) {
          ThrowFileError(where, name, "data file: {} to {} in steps of {} is not a range", min, max,
                         step);
        }
        const int64_t count = (max - min) / step + 1;
        if (count > kMaxDataFiles)
          ThrowFileError(where, name, "{} data files, more than {}", count, kMaxDataFiles);
        for (int64_t i = 0; i < count; ++i)
          h.data_files.push_back(FormatDataFileName(words[0], min + i * step, where, name));
      } else {
        ThrowFileError(where, name,
                       "data file '{}': expected one file, 'LIST [subdim]' or 'FORMAT MIN MAX "
                       "STEP [subdim]'",
                       value);
      }
    } else if (field == "line skip" || field == "lineskip") {
      h.line_skip = ParseInt(value, field, where, name);
      if (h.line_skip < 0) ThrowFileError(where, name, "line skip {} is negative", h.line_skip);
    } else if (field == "byte skip" || field == "byteskip") {
      h.byte_skip = ParseInt(value, field, where, name);
      if (h.byte_skip < -1)
        ThrowFileError(where, name, "byte skip {} (>= 0, or -1 for data at the end)", h.byte_skip);
    }
    // Other fields (kinds, centers, space, space origin, content, ...) do not
    // change the voxels or their spacing.
  }
  if (!have_type || !have_dimension || !have_sizes || !have_encoding) {
    ThrowFileError(where, name, "header lacks a required field (type, dimension, sizes, encoding)");
  }
  if (list && h.data_files.empty()) ThrowFileError(where, name, "data file: LIST names no file");
  CheckedVolumeBytes(fmt::format("ReadNrrd: '{}'", name), h.dims, h.type);
  CheckSpacing(h.spacing, where, name);
  if (!h.data_files.empty()) {
    // Each file holds one equal part: the first `subdim` axes' worth of voxels.
    const int subdim = h.subdim != 0 ? h.subdim : (h.data_files.size() == 1 ? 3 : 2);
    if (subdim < 1 || subdim > 3)
      ThrowFileError(where, name, "data file subdim {} (1..3 for a 3D volume)", subdim);
    int64_t per_file = 1, parts = 1;
    for (int a = 0; a < 3; ++a) (a < subdim ? per_file : parts) *= h.dims[a];
    if (parts != static_cast<int64_t>(h.data_files.size())) {
      ThrowFileError(where, name,
                     "{} data files, the sizes {} {} {} make {} parts of {} dimension(s)",
                     h.data_files.size(), h.dims.x, h.dims.y, h.dims.z, parts, subdim);
    }
    h.subdim = subdim;
  }
  return h;
}

// Skips `lines` lines of `in` (before any decoding, as NRRD's "line skip").
void SkipLines(std::istream& in, int64_t lines, std::string_view where, std::string_view name) {
  for (int64_t i = 0; i < lines; ++i) {
    in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    if (in.eof()) ThrowFileError(where, name, "line skip {} is past the end of the file", lines);
  }
}

// One data file's (or the attached data's) `count` bytes.
std::vector<uint8_t> ReadNrrdPart(std::istream& in, const NrrdHeader& h, size_t count,
                                  std::string_view name) {
  constexpr std::string_view where = "ReadNrrd";
  SkipLines(in, h.line_skip, where, name);
  if (h.encoding == Encoding::kRaw) {
    if (h.byte_skip == -1) {
      // The data are the file's last bytes (after a header of another format).
      const std::streamoff remaining = RemainingBytes(in);
      if (remaining < 0) ThrowFileError(where, name, "byte skip -1 needs a seekable file");
      if (static_cast<size_t>(remaining) < count)
        ThrowFileError(where, name, "short data: {} bytes, the header says {}", remaining, count);
      in.seekg(static_cast<std::streamoff>(remaining) - static_cast<std::streamoff>(count),
               std::ios::cur);
    } else if (h.byte_skip > 0) {
      in.ignore(h.byte_skip);
      if (in.gcount() != h.byte_skip)
        ThrowFileError(where, name, "byte skip {} is past the end of the file", h.byte_skip);
    }
    return ReadExactly(in, count, /*exact=*/true, where, name);
  }
  std::unique_ptr<Decoder> decoder;
  if (h.encoding == Encoding::kGzip) {
    decoder = std::make_unique<GzipDecoder>(in, where, name);
  } else {
    decoder = std::make_unique<Bzip2Decoder>(in, where, name);
  }
  return ReadDecoded(*decoder, count, h.byte_skip, where, name);
}

// The voxels of `h`, read part by part through `open_part(i)` (the stream
// and the name of part i); endianness swapped to native.
template <class OpenPart>
Volume ReadNrrdData(const NrrdHeader& h, size_t parts, OpenPart&& open_part,
                    std::string_view header_name) {
  Volume v;
  v.dims = h.dims;
  v.spacing = h.spacing;
  v.type = h.type;
  const size_t bytes =
      CheckedVolumeBytes(fmt::format("ReadNrrd: '{}'", header_name), h.dims, h.type);
  const size_t per_part = bytes / parts;
  for (size_t i = 0; i < parts; ++i) {
    auto [stream, name] = open_part(i);
    std::vector<uint8_t> part = ReadNrrdPart(*stream, h, per_part, name);
    if (parts == 1) {
      v.bytes = std::move(part);
    } else {
      if (i == 0) v.bytes.reserve(bytes);
      v.bytes.insert(v.bytes.end(), part.begin(), part.end());
    }
  }
  if (h.big_endian) SwapBytes(v.bytes, BytesPerScalar(h.type));
  v.FitNormalization();
  return v;
}

// ---- NIfTI-1 / NIfTI-2 ----

template <class T>
void SwapValue(T& v) {
  auto* b = reinterpret_cast<uint8_t*>(&v);
  std::reverse(b, b + sizeof(T));
}

// A NIfTI datatype code (nifti1.h DT_*) -> our type; others refused.
ScalarType NiftiType(int code, std::string_view where, std::string_view name) {
  switch (code) {
    case DT_UINT8:
      return ScalarType::kUint8;
    case DT_INT8:
      return ScalarType::kInt8;
    case DT_INT16:
      return ScalarType::kInt16;
    case DT_UINT16:
      return ScalarType::kUint16;
    case DT_INT32:
      return ScalarType::kInt32;
    case DT_UINT32:
      return ScalarType::kUint32;
    case DT_FLOAT32:
      return ScalarType::kFloat32;
    case DT_FLOAT64:
      return ScalarType::kFloat64;
    default:
      ThrowFileError(where, name,
                     "NIfTI datatype {} is not supported ((u)int8/16/32, float32 or float64; "
                     "RGB, complex and 64-bit integers are not)",
                     code);
  }
}

// What the readers need from either header version.
struct NiftiInfo {
  int64_t dim[8] = {};
  double pixdim[8] = {};
  int datatype = 0, bitpix = 0;
  int64_t vox_offset = 0;
  double scl_slope = 0, scl_inter = 0;
  bool swap = false;
  int header_bytes = 0;
};

// The fields the reader uses from either header layout (nifti_1_header or
// nifti_2_header: same names, wider types in NIfTI-2), byte-swapped when the
// file's order is not ours. `single` is the single-file magic, `pair` the
// .hdr/.img one.
template <class Header>
void CopyNiftiFields(const uint8_t* raw, const char* single, const char* pair, NiftiInfo& info,
                     std::string_view name) {
  constexpr std::string_view where = "ReadNifti";
  Header h;
  std::memcpy(&h, raw, sizeof h);
  if (std::memcmp(h.magic, single, 4) != 0) {
    if (std::memcmp(h.magic, pair, 4) == 0)
      ThrowFileError(where, name, "a .hdr/.img pair (magic '{}'): only single-file .nii", pair);
    ThrowFileError(where, name, "not a NIfTI file (magic is not '{}')", single);
  }
  const auto fix = [&](auto& v) {
    if (info.swap) SwapValue(v);
  };
  for (int i = 0; i < 8; ++i) {
    fix(h.dim[i]);
    fix(h.pixdim[i]);
    info.dim[i] = h.dim[i];
    info.pixdim[i] = h.pixdim[i];
  }
  fix(h.datatype);
  fix(h.bitpix);
  fix(h.vox_offset);
  fix(h.scl_slope);
  fix(h.scl_inter);
  info.datatype = h.datatype;
  info.bitpix = h.bitpix;
  // NIfTI-1 stores the offset as a float.
  if (!std::isfinite(static_cast<double>(h.vox_offset)) || h.vox_offset < 0 ||
      static_cast<double>(h.vox_offset) > 1e12) {
    ThrowFileError(where, name, "vox_offset {} is not a file offset",
                   static_cast<double>(h.vox_offset));
  }
  info.vox_offset = static_cast<int64_t>(h.vox_offset);
  info.scl_slope = h.scl_slope;
  info.scl_inter = h.scl_inter;
}

NiftiInfo ReadNiftiHeader(Decoder& d, std::string_view name) {
  constexpr std::string_view where = "ReadNifti";
  std::array<uint8_t, sizeof(nifti_2_header)> raw{};
  if (d.Read(raw.data(), 4) != 4) ThrowFileError(where, name, "not a NIfTI file (too short)");
  int32_t sizeof_hdr;
  std::memcpy(&sizeof_hdr, raw.data(), 4);
  NiftiInfo info;
  int32_t swapped = sizeof_hdr;
  SwapValue(swapped);
  if (sizeof_hdr == 348 || sizeof_hdr == 540) {
    info.swap = false;
  } else if (swapped == 348 || swapped == 540) {
    info.swap = true;
    sizeof_hdr = swapped;
  } else {
    ThrowFileError(where, name, "not a NIfTI file (header size {}, expected 348 or 540)",
                   sizeof_hdr);
  }
  info.header_bytes = sizeof_hdr;
  if (d.Read(raw.data() + 4, static_cast<size_t>(sizeof_hdr - 4)) !=
      static_cast<size_t>(sizeof_hdr - 4)) {
    ThrowFileError(where, name, "truncated NIfTI header");
  }
  if (sizeof_hdr == 348) {
    CopyNiftiFields<nifti_1_header>(raw.data(), "n+1", "ni1", info, name);
  } else {
    CopyNiftiFields<nifti_2_header>(raw.data(), "n+2", "ni2", info, name);
  }
  return info;
}

Volume ReadNiftiFrom(Decoder& d, std::string_view name) {
  constexpr std::string_view where = "ReadNifti";
  const NiftiInfo info = ReadNiftiHeader(d, name);
  const int64_t rank = info.dim[0];
  if (rank < 1 || rank > 7) ThrowFileError(where, name, "dim[0] = {} (1..7)", rank);
  for (int i = 4; i <= rank; ++i) {
    if (info.dim[i] != 1) {
      ThrowFileError(where, name,
                     "{}D data ({} along axis {}): only 3D volumes are read (extract one volume "
                     "first)",
                     rank, info.dim[i], i);
    }
  }
  glm::ivec3 dims(1);
  glm::dvec3 spacing(1.0);
  for (int a = 0; a < 3 && a < rank; ++a) {
    const int64_t n = info.dim[a + 1];
    if (n < 1 || n > kMaxVolumeExtent)
      ThrowFileError(where, name, "dim[{}] = {}: each extent must be in [1, {}]", a + 1, n,
                     kMaxVolumeExtent);
    dims[a] = static_cast<int>(n);
    // pixdim may carry the sign of a flip (the orientation is in the
    // q/s-form, which the axis-aligned box does not use); 0 means unknown.
    const double p = std::abs(info.pixdim[a + 1]);
    spacing[a] = p > 0 ? p : 1.0;
  }
  const ScalarType type = NiftiType(info.datatype, where, name);
  if (info.bitpix != 8 * BytesPerScalar(type)) {
    ThrowFileError(where, name, "bitpix {} does not match datatype {} ({} bits)", info.bitpix,
                   ScalarTypeName(type), 8 * BytesPerScalar(type));
  }
  CheckSpacing(spacing, where, name);
  const size_t bytes = CheckedVolumeBytes(fmt::format("ReadNifti: '{}'", name), dims, type);
  if (info.vox_offset < info.header_bytes) {
    ThrowFileError(where, name, "vox_offset {} is inside the {}-byte header", info.vox_offset,
                   info.header_bytes);
  }
  // Extensions between the header and the data are skipped; bytes after the
  // voxels (padding some writers leave) are ignored.
  std::vector<uint8_t> skip(static_cast<size_t>(
      std::min<int64_t>(std::max<int64_t>(info.vox_offset - info.header_bytes, 1),
                        static_cast<int64_t>(kFirstChunk))));
  for (int64_t left = info.vox_offset - info.header_bytes; left > 0;) {
    const size_t n =
        d.Read(skip.data(),
               static_cast<size_t>(std::min<int64_t>(left, static_cast<int64_t>(skip.size()))));
    if (n == 0) ThrowFileError(where, name, "vox_offset {} is past the end", info.vox_offset);
    left -= static_cast<int64_t>(n);
  }
  Volume v;
  v.dims = dims;
  v.spacing = spacing;
  v.type = type;
  while (v.bytes.size() < bytes) {
    const size_t old = v.bytes.size();
    const size_t n = NextChunk(old, bytes);
    v.bytes.resize(old + n);
    const size_t got = d.Read(v.bytes.data() + old, n);
    if (got < n)
      ThrowFileError(where, name, "short data: {} bytes, the header says {}", old + got, bytes);
  }
  if (info.swap) SwapBytes(v.bytes, BytesPerScalar(type));
  ApplyLinearScale(v, info.scl_slope, info.scl_inter);
  v.FitNormalization();
  return v;
}

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

}  // namespace

QVisHeader ReadQVisHeader(std::istream& dat, std::string_view name) {
  constexpr std::string_view where = "ReadQVis";
  QVisHeader h;
  bool have_object = false, have_resolution = false, have_format = false;
  size_t header_bytes = 0;
  std::string line;
  while (ReadHeaderLine(dat, line, header_bytes, where, name)) {
    const std::string_view l = Trim(line);
    if (l.empty()) continue;
    const size_t colon = l.find(':');
    if (colon == std::string_view::npos)
      ThrowFileError(where, name, "line '{}' is not 'Key: value'", l.substr(0, 64));
    const std::string_view key = Trim(l.substr(0, colon));
    const std::string_view value = Trim(l.substr(colon + 1));
    if (key == "ObjectFileName") {
      if (value.empty()) ThrowFileError(where, name, "ObjectFileName is empty");
      h.object_file = std::string(value);
      have_object = true;
    } else if (key == "Resolution") {
      h.dims = ParseDims(value, "Resolution", where, name);
      have_resolution = true;
    } else if (key == "SliceThickness") {
      const auto words = SplitWords(value);
      if (words.size() != 3)
        ThrowFileError(where, name, "SliceThickness: expected 3 values, got '{}'", value);
      for (int a = 0; a < 3; ++a)
        h.spacing[a] = ParseDouble(words[a], "SliceThickness", where, name);
    } else if (key == "Format") {
      if (value == "UCHAR" || value == "BYTE") {
        h.type = ScalarType::kUint8;
      } else if (value == "USHORT") {
        h.type = ScalarType::kUint16;
      } else if (value == "FLOAT") {
        h.type = ScalarType::kFloat32;
      } else {
        ThrowFileError(where, name, "Format '{}' is not supported (UCHAR, USHORT or FLOAT)", value);
      }
      have_format = true;
    }
  }
  if (!have_object) ThrowFileError(where, name, "no ObjectFileName line");
  if (!have_resolution) ThrowFileError(where, name, "no Resolution line");
  if (!have_format) ThrowFileError(where, name, "no Format line");
  CheckedVolumeBytes(fmt::format("ReadQVis: '{}'", name), h.dims, h.type);
  CheckSpacing(h.spacing, where, name);
  return h;
}

Volume ReadQVisRaw(std::istream& raw, const QVisHeader& header, std::string_view name) {
  Volume v;
  v.dims = header.dims;
  v.spacing = header.spacing;
  v.type = header.type;
  v.bytes = ReadExactly(raw, CheckedVolumeBytes("ReadQVis", header.dims, header.type),
                        /*exact=*/true, "ReadQVis", name);
  v.FitNormalization();
  return v;
}

Volume ReadQVis(const fs::path& dat_path) {
  auto dat = OpenBinary(dat_path, "ReadQVis");
  const QVisHeader header = ReadQVisHeader(dat, dat_path.string());
  const fs::path raw_path = dat_path.parent_path() / header.object_file;
  auto raw = OpenBinary(raw_path, "ReadQVis");
  return ReadQVisRaw(raw, header, raw_path.string());
}

void WriteQVisHeader(std::ostream& dat, const Volume& volume, std::string_view object_file) {
  dat << fmt::format(
      "ObjectFileName: {}\nResolution: {} {} {}\nSliceThickness: {} {} {}\nFormat: {}\n"
      "Software: {}\n",
      object_file, volume.dims.x, volume.dims.y, volume.dims.z, volume.spacing.x, volume.spacing.y,
      volume.spacing.z, QVisFormatName(volume.type), kFileMark);
}

void WriteQVisRaw(std::ostream& raw, const Volume& volume) {
  raw.write(reinterpret_cast<const char*>(volume.bytes.data()),
            static_cast<std::streamsize>(volume.bytes.size()));
}

void WriteQVis(const fs::path& dat_path, const Volume& volume) {
  fs::path raw_path = dat_path;
  raw_path.replace_extension(".raw");
  AtomicWriteStream(raw_path, [&](std::ostream& out) { WriteQVisRaw(out, volume); });
  AtomicWriteStream(dat_path, [&](std::ostream& out) {
    WriteQVisHeader(out, volume, raw_path.filename().string());
  });
}

Volume ReadNrrd(std::istream& in, std::string_view name) {
  const NrrdHeader h = ReadNrrdHeader(in, name);
  if (!h.data_files.empty()) {
    ThrowFileError("ReadNrrd", name, "detached data file '{}' cannot be read from a stream",
                   h.data_files.front());
  }
  return ReadNrrdData(
      h, 1, [&](size_t) { return std::pair(&in, std::string(name)); }, name);
}

Volume ReadNrrd(const fs::path& path) {
  auto in = OpenBinary(path, "ReadNrrd");
  const NrrdHeader h = ReadNrrdHeader(in, path.string());
  if (h.data_files.empty()) {
    return ReadNrrdData(
        h, 1, [&](size_t) { return std::pair(&in, path.string()); }, path.string());
  }
  std::ifstream data;
  return ReadNrrdData(
      h, h.data_files.size(),
      [&](size_t i) {
        const fs::path data_path = path.parent_path() / h.data_files[i];
        data = OpenBinary(data_path, "ReadNrrd");
        return std::pair(static_cast<std::istream*>(&data), data_path.string());
      },
      path.string());
}

void WriteNrrd(std::ostream& out, const Volume& volume, NrrdEncoding encoding) {
  out << fmt::format(
      "NRRD0004\n# written by ibr\ntype: {}\ndimension: 3\nsizes: {} {} {}\nspacings: {} {} "
      "{}\nendian: "
      "little\nencoding: {}\n\n",
      NrrdTypeName(volume.type), volume.dims.x, volume.dims.y, volume.dims.z, volume.spacing.x,
      volume.spacing.y, volume.spacing.z, encoding == NrrdEncoding::kRaw ? "raw" : "gzip");
  if (encoding == NrrdEncoding::kRaw) {
    out.write(reinterpret_cast<const char*>(volume.bytes.data()),
              static_cast<std::streamsize>(volume.bytes.size()));
  } else {
    Gzip(out, volume.bytes);
  }
}

void WriteNrrd(const fs::path& path, const Volume& volume, NrrdEncoding encoding) {
  AtomicWriteStream(path, [&](std::ostream& out) { WriteNrrd(out, volume, encoding); });
}

Volume ReadNifti(std::istream& in, std::string_view name) {
  // .nii.gz: the whole file is one gzip stream (magic 1f 8b).
  const int c0 = in.peek();
  if (c0 == 0x1f) {
    GzipDecoder gz(in, "ReadNifti", name);
    return ReadNiftiFrom(gz, name);
  }
  RawDecoder raw(in);
  return ReadNiftiFrom(raw, name);
}

Volume ReadNifti(const fs::path& path) {
  auto in = OpenBinary(path, "ReadNifti");
  return ReadNifti(in, path.string());
}

Volume ReadVolume(const fs::path& path) {
  const std::string file = path.filename().string();
  const std::string ext = path.extension().string();
  if (ext == ".dat") return ReadQVis(path);
  if (ext == ".nrrd" || ext == ".nhdr") return ReadNrrd(path);
  if (EndsWith(file, ".nii") || EndsWith(file, ".nii.gz")) return ReadNifti(path);
  std::error_code ec;
  if (fs::is_directory(path, ec)) return ReadDicomSeries(path);
  ThrowFileError("ReadVolume", path,
                 "unknown volume format '{}' (.dat for QVis, .nrrd or .nhdr, .nii or .nii.gz, or "
                 "a folder of DICOM slices)",
                 ext);
}

}  // namespace core
