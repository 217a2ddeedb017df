#include "core/volume_io.h"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <istream>
#include <map>
#include <ostream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace core {
namespace {

namespace fs = std::filesystem;

constexpr size_t kMaxHeaderLine = 4096;         // characters in one header line
constexpr size_t kMaxHeaderBytes = 65536;       // characters in a whole header
constexpr size_t kReadChunk = size_t{1} << 24;  // 16 MiB: largest step of a chunked read

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
    const size_t n = std::min(kReadChunk, expected - old);
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

// ---- gzip (zlib) ----

std::vector<uint8_t> Gunzip(std::istream& in, size_t expected, std::string_view where,
                            std::string_view name) {
  z_stream z{};
  // 15 + 32: a zlib or gzip header, detected automatically.
  if (inflateInit2(&z, 15 + 32) != Z_OK) ThrowFileError(where, name, "zlib: inflateInit2 failed");
  std::vector<uint8_t> out;
  std::vector<char> input(size_t{1} << 16);
  int status = Z_OK;
  bool input_done = false;
  try {
    while (status != Z_STREAM_END) {
      if (z.avail_in == 0 && !input_done) {
        in.read(input.data(), static_cast<std::streamsize>(input.size()));
        z.next_in = reinterpret_cast<Bytef*>(input.data());
        z.avail_in = static_cast<uInt>(in.gcount());
        if (z.avail_in == 0) input_done = true;
      }
      if (out.size() == expected) {
        // All voxels are in; the stream must end here (a one-byte probe tells).
        uint8_t probe;
        z.next_out = &probe;
        z.avail_out = 1;
        status = inflate(&z, Z_NO_FLUSH);
        if (z.avail_out == 0)
          ThrowFileError(where, name, "gzip data longer than the {} bytes the header says",
                         expected);
      } else {
        const size_t old = out.size();
        const size_t n = std::min(kReadChunk, expected - old);
        out.resize(old + n);
        z.next_out = out.data() + old;
        z.avail_out = static_cast<uInt>(n);
        status = inflate(&z, Z_NO_FLUSH);
        out.resize(old + n - z.avail_out);
      }
      if (status == Z_BUF_ERROR && input_done) {
        ThrowFileError(where, name, "truncated gzip data: {} of {} bytes", out.size(), expected);
      }
      if (status != Z_OK && status != Z_STREAM_END && status != Z_BUF_ERROR) {
        ThrowFileError(where, name, "corrupt gzip data ({})", z.msg ? z.msg : "zlib error");
      }
    }
  } catch (...) {
    inflateEnd(&z);
    throw;
  }
  inflateEnd(&z);
  if (out.size() != expected) {
    ThrowFileError(where, name, "short gzip data: {} bytes, the header says {}", out.size(),
                   expected);
  }
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
  }
  return "";
}

// ---- NRRD ----

ScalarType ParseNrrdType(std::string_view value, std::string_view where, std::string_view name) {
  static const std::map<std::string_view, ScalarType> kTypes = {
      {"uchar", ScalarType::kUint8},
      {"unsigned char", ScalarType::kUint8},
      {"uint8", ScalarType::kUint8},
      {"uint8_t", ScalarType::kUint8},
      {"ushort", ScalarType::kUint16},
      {"unsigned short", ScalarType::kUint16},
      {"unsigned short int", ScalarType::kUint16},
      {"uint16", ScalarType::kUint16},
      {"uint16_t", ScalarType::kUint16},
      {"float", ScalarType::kFloat32}};
  const auto it = kTypes.find(value);
  if (it == kTypes.end()) {
    ThrowFileError(where, name, "type '{}' is not supported (uint8, uint16 or float)", value);
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

struct NrrdHeader {
  glm::ivec3 dims{0};
  glm::dvec3 spacing{1.0};
  ScalarType type = ScalarType::kUint8;
  NrrdEncoding encoding = NrrdEncoding::kRaw;
  bool big_endian = false;
  std::string data_file;  // detached data; empty when attached
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
  bool have_spacings = false;
  while (ReadHeaderLine(in, line, header_bytes, where, name)) {
    std::string_view l = line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
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
        h.encoding = NrrdEncoding::kRaw;
      } else if (value == "gzip" || value == "gz") {
        h.encoding = NrrdEncoding::kGzip;
      } else {
        ThrowFileError(where, name, "encoding '{}' is not supported (raw or gzip)", value);
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
      if (value.empty() || SplitWords(value).size() != 1) {
        ThrowFileError(where, name, "data file '{}': only one detached file is supported", value);
      }
      h.data_file = std::string(value);
    } else if (field == "line skip" || field == "lineskip" || field == "byte skip" ||
               field == "byteskip") {
      if (ParseInt(value, field, where, name) != 0)
        ThrowFileError(where, name, "'{}' is not supported", field);
    }
    // Other fields (kinds, centers, space, space origin, content, ...) do not
    // change the voxels or their spacing.
  }
  if (!have_type || !have_dimension || !have_sizes || !have_encoding) {
    ThrowFileError(where, name, "header lacks a required field (type, dimension, sizes, encoding)");
  }
  CheckedVolumeBytes(fmt::format("ReadNrrd: '{}'", name), h.dims, h.type);
  CheckSpacing(h.spacing, where, name);
  return h;
}

Volume ReadNrrdData(std::istream& data, const NrrdHeader& h, std::string_view name) {
  constexpr std::string_view where = "ReadNrrd";
  Volume v;
  v.dims = h.dims;
  v.spacing = h.spacing;
  v.type = h.type;
  const size_t bytes = CheckedVolumeBytes(where, h.dims, h.type);
  v.bytes = h.encoding == NrrdEncoding::kRaw ? ReadExactly(data, bytes, /*exact=*/true, where, name)
                                             : Gunzip(data, bytes, where, name);
  if (h.big_endian) SwapBytes(v.bytes, BytesPerScalar(h.type));
  return v;
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
      "ObjectFileName: {}\nResolution: {} {} {}\nSliceThickness: {} {} {}\nFormat: {}\n",
      object_file, volume.dims.x, volume.dims.y, volume.dims.z, volume.spacing.x, volume.spacing.y,
      volume.spacing.z, QVisFormatName(volume.type));
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
  if (!h.data_file.empty()) {
    ThrowFileError("ReadNrrd", name, "detached data file '{}' cannot be read from a stream",
                   h.data_file);
  }
  return ReadNrrdData(in, h, name);
}

Volume ReadNrrd(const fs::path& path) {
  auto in = OpenBinary(path, "ReadNrrd");
  const NrrdHeader h = ReadNrrdHeader(in, path.string());
  if (h.data_file.empty()) return ReadNrrdData(in, h, path.string());
  const fs::path data_path = path.parent_path() / h.data_file;
  auto data = OpenBinary(data_path, "ReadNrrd");
  return ReadNrrdData(data, h, data_path.string());
}

void WriteNrrd(std::ostream& out, const Volume& volume, NrrdEncoding encoding) {
  out << fmt::format(
      "NRRD0004\n# written by ibr\ntype: {}\ndimension: 3\nsizes: {} {} {}\nspacings: {} {} "
      "{}\nendian: "
      "little\nencoding: {}\n\n",
      volume.type == ScalarType::kUint8    ? "uint8"
      : volume.type == ScalarType::kUint16 ? "uint16"
                                           : "float",
      volume.dims.x, volume.dims.y, volume.dims.z, volume.spacing.x, volume.spacing.y,
      volume.spacing.z, encoding == NrrdEncoding::kRaw ? "raw" : "gzip");
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

Volume ReadVolume(const fs::path& path) {
  const std::string ext = path.extension().string();
  if (ext == ".dat") return ReadQVis(path);
  if (ext == ".nrrd" || ext == ".nhdr") return ReadNrrd(path);
  ThrowFileError("ReadVolume", path, "unknown volume format '{}' (.dat for QVis, .nrrd or .nhdr)",
                 ext);
}

}  // namespace core
