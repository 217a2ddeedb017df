#include "core/ply_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>

#include "core/error.h"
#include "core/memory_budget.h"

namespace core {
namespace {

// A header line longer than this, or more lines than this, is not PLY: the
// limits keep arbitrary bytes from growing the header without bound.
constexpr size_t kMaxHeaderLine = 4096;
constexpr int kMaxHeaderLines = 10000;

struct ScalarType {
  int bytes = 0;
  bool is_float = false;
  bool is_signed = false;
};

std::optional<ScalarType> ParseType(std::string_view name) {
  if (name == "char" || name == "int8") return ScalarType{1, false, true};
  if (name == "uchar" || name == "uint8") return ScalarType{1, false, false};
  if (name == "short" || name == "int16") return ScalarType{2, false, true};
  if (name == "ushort" || name == "uint16") return ScalarType{2, false, false};
  if (name == "int" || name == "int32") return ScalarType{4, false, true};
  if (name == "uint" || name == "uint32") return ScalarType{4, false, false};
  if (name == "float" || name == "float32") return ScalarType{4, true, true};
  if (name == "double" || name == "float64") return ScalarType{8, true, true};
  return std::nullopt;
}

bool IsIndexList(const PlyProperty& p) {
  return p.is_list() && (p.name == "vertex_indices" || p.name == "vertex_index");
}

std::vector<std::string_view> Words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Where a value sits, for messages: "face 57", "vertex 3".
struct Place {
  std::string_view element;
  uint64_t row = 0;
};

}  // namespace
}  // namespace core

template <>
struct fmt::formatter<core::Place> : fmt::formatter<std::string> {
  auto format(const core::Place& p, format_context& ctx) const {
    return fmt::format_to(ctx.out(), "{} {}", p.element, p.row);
  }
};

namespace core {
namespace {

// The body, binary or ascii, read value by value with the place named on error.
class BodyReader {
 public:
  BodyReader(std::string_view body, PlyHeader::Format format, const std::string& where)
      : body_(body), format_(format), where_(where) {}

  // `what` names the value for messages ("element 'face' row 3").
  double Real(const ScalarType& type, const Place& what) {
    if (format_ == PlyHeader::Format::kAscii) return Ascii<double>(what, "a number");
    return Binary(type, what);
  }

  int64_t Integer(const ScalarType& type, const Place& what) {
    if (type.is_float) ThrowInputError(where_, "{}: a list length or index of float type", what);
    if (format_ == PlyHeader::Format::kAscii) return Ascii<int64_t>(what, "an integer");
    return static_cast<int64_t>(Binary(type, what));
  }

  // Bytes (binary) or characters (ascii) not yet read.
  size_t remaining() const { return body_.size() - pos_; }

  // True when only whitespace (ascii) or nothing (binary) is left.
  bool AtEnd() {
    if (format_ == PlyHeader::Format::kAscii) SkipSpace();
    return pos_ == body_.size();
  }

 private:
  static std::string Shorten(std::string_view s) {
    return std::string(s.substr(0, 24)) + (s.size() > 24 ? "..." : "");
  }

  void SkipSpace() {
    while (pos_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
  }

  std::string_view Token(const Place& what) {
    SkipSpace();
    const size_t start = pos_;
    while (pos_ < body_.size() && !std::isspace(static_cast<unsigned char>(body_[pos_]))) ++pos_;
    if (pos_ == start) ThrowInputError(where_, "{}: the file ends here", what);
    return body_.substr(start, pos_ - start);
  }

  // The next token as a T; `kind` names T for the message.
  template <typename T>
  T Ascii(const Place& what, std::string_view kind) {
    const std::string_view token = Token(what);
    T value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size()) {
      ThrowInputError(where_, "{}: '{}' is not {}", what, Shorten(token), kind);
    }
    return value;
  }

  double Binary(const ScalarType& type, const Place& what) {
    if (remaining() < static_cast<size_t>(type.bytes)) {
      ThrowInputError(where_, "{}: the file ends here", what);
    }
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, type.bytes);
    pos_ += type.bytes;
    const bool big = format_ == PlyHeader::Format::kBinaryBigEndian;
    if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + type.bytes);
    switch (type.bytes) {
      case 1:
        return type.is_signed ? static_cast<double>(static_cast<int8_t>(b[0])) : b[0];
      case 2: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return type.is_signed ? static_cast<double>(static_cast<int16_t>(v)) : v;
      }
      case 4: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        if (type.is_float) return static_cast<double>(std::bit_cast<float>(v));
        return type.is_signed ? static_cast<double>(static_cast<int32_t>(v)) : v;
      }
      default: {
        uint64_t v;
        std::memcpy(&v, b, 8);
        return std::bit_cast<double>(v);
      }
    }
  }

  std::string_view body_;
  size_t pos_ = 0;
  PlyHeader::Format format_;
  const std::string& where_;
};

// The smallest a row of `e` can take in a binary body (lists empty).
uint64_t MinRowBytes(const PlyElement& e) {
  uint64_t bytes = 0;
  for (const PlyProperty& p : e.properties) {
    bytes += static_cast<uint64_t>(ParseType(p.is_list() ? p.count_type : p.type)->bytes);
  }
  return bytes;
}

// Reads (and discards) one property value or list.
void SkipProperty(BodyReader& r, const PlyProperty& p, const Place& what,
                  const std::string& where) {
  const ScalarType item = *ParseType(p.type);
  if (!p.is_list()) {
    r.Real(item, what);
    return;
  }
  const int64_t n = r.Integer(*ParseType(p.count_type), what);
  if (n < 0) ThrowInputError(where, "{}: list '{}' has negative length {}", what, p.name, n);
  // Each item takes at least one byte (binary) or two characters (ascii).
  if (static_cast<uint64_t>(n) > r.remaining()) {
    ThrowInputError(where, "{}: list '{}' of {} items runs past the end of the file", what, p.name,
                    n);
  }
  for (int64_t i = 0; i < n; ++i) r.Real(item, what);
}

}  // namespace

const PlyElement* PlyHeader::Find(const std::string& name) const {
  for (const PlyElement& e : elements)
    if (e.name == name) return &e;
  return nullptr;
}

PlyHeader ReadPlyHeader(std::istream& in, const std::string& where) {
  PlyHeader header;
  bool have_format = false;
  for (int n = 0;; ++n) {
    if (n >= kMaxHeaderLines) ThrowInputError(where, "no end_header in the first {} lines", n);
    std::string line;
    char c;
    while (in.get(c) && c != '\n') {
      if (line.size() >= kMaxHeaderLine) {
        ThrowInputError(where, "header line {} is longer than {} characters: not a PLY header",
                        n + 1, kMaxHeaderLine);
      }
      line.push_back(c);
    }
    if (!in && line.empty()) ThrowInputError(where, "the file ends before end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (n == 0) {
      if (line != "ply") ThrowInputError(where, "not a PLY file (does not start with 'ply')");
      continue;
    }
    const std::vector<std::string_view> w = Words(line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "comment" || w[0] == "obj_info") {
      const size_t at = line.find(w[0]) + w[0].size();
      std::string text = line.substr(std::min(line.size(), at + 1));
      header.comments.push_back(std::move(text));
    } else if (w[0] == "format") {
      if (w.size() != 3) ThrowInputError(where, "header line {}: bad format line", n + 1);
      if (w[1] == "ascii") {
        header.format = PlyHeader::Format::kAscii;
      } else if (w[1] == "binary_little_endian") {
        header.format = PlyHeader::Format::kBinaryLittleEndian;
      } else if (w[1] == "binary_big_endian") {
        header.format = PlyHeader::Format::kBinaryBigEndian;
      } else {
        ThrowInputError(where, "header line {}: unknown format '{}'", n + 1, w[1]);
      }
      have_format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3) ThrowInputError(where, "header line {}: bad element line", n + 1);
      PlyElement e;
      e.name = std::string(w[1]);
      const auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || ptr != w[2].data() + w[2].size()) {
        ThrowInputError(where, "header line {}: element '{}' count '{}' is not a count", n + 1,
                        e.name, w[2]);
      }
      header.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (header.elements.empty()) {
        ThrowInputError(where, "header line {}: a property before any element", n + 1);
      }
      PlyProperty p;
      if (w.size() == 5 && w[1] == "list") {
        p.count_type = std::string(w[2]);
        p.type = std::string(w[3]);
        p.name = std::string(w[4]);
        const std::optional<ScalarType> count = ParseType(p.count_type);
        if (!count || count->is_float) {
          ThrowInputError(where, "header line {}: list length type '{}' is not an integer type",
                          n + 1, p.count_type);
        }
      } else if (w.size() == 3) {
        p.type = std::string(w[1]);
        p.name = std::string(w[2]);
      } else {
        ThrowInputError(where, "header line {}: bad property line", n + 1);
      }
      if (!ParseType(p.type)) {
        ThrowInputError(where, "header line {}: unknown property type '{}'", n + 1, p.type);
      }
      header.elements.back().properties.push_back(std::move(p));
    } else {
      ThrowInputError(where, "header line {}: unknown keyword '{}'", n + 1, w[0]);
    }
  }
  if (!have_format) ThrowInputError(where, "no format line in the header");
  return header;
}

uint64_t EstimatePlyMeshBytes(const PlyHeader& header) {
  // Per vertex: position, normal (computed if absent), uv; per triangle 3
  // indices. Faces give at least one triangle each; a strip row's triangles
  // are checked when its length is read.
  constexpr uint64_t kVertexBytes = sizeof(glm::vec3) * 2 + sizeof(glm::vec2);
  constexpr uint64_t kTriangleBytes = 3 * sizeof(uint32_t);
  uint64_t bytes = 0;
  for (const PlyElement& e : header.elements) {
    const uint64_t count = std::min<uint64_t>(e.count, uint64_t{1} << 40);
    if (e.name == "vertex") bytes += count * kVertexBytes;
    if (e.name == "face") bytes += count * kTriangleBytes;
  }
  return bytes;
}

PlyMesh ReadPly(std::istream& in, const std::string& where) {
  const PlyHeader header = ReadPlyHeader(in, where);
  const PlyElement* vertex = header.Find("vertex");
  if (!vertex) ThrowInputError(where, "no 'vertex' element: not a mesh");
  if (!header.Find("face") && !header.Find("tristrips")) {
    ThrowInputError(where,
                    "no 'face' or 'tristrips' element: a point cloud ({} vertices), not a "
                    "mesh",
                    vertex->count);
  }
  for (const PlyElement& e : header.elements) {
    if (e.name == "face" || e.name == "tristrips") continue;
    for (const PlyProperty& p : e.properties) {
      if (IsIndexList(p)) {
        ThrowInputError(where,
                        "element '{}' ({} rows) holds vertex indices this reader does not decode "
                        "(only 'face' and 'tristrips'); its surface would be lost: convert the "
                        "file to faces first (e.g. MeshLab)",
                        e.name, e.count);
      }
    }
  }
  if (vertex->count > std::numeric_limits<uint32_t>::max()) {
    ThrowInputError(where, "{} vertices: more than 32-bit indices address", vertex->count);
  }
  CheckMemory(EstimatePlyMeshBytes(header), where,
              fmt::format("the mesh ({} vertices, {} faces)", vertex->count,
                          header.Find("face") ? header.Find("face")->count : 0));

  // The body, whole: binary sizes are checked against it before any row is read.
  std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (header.format != PlyHeader::Format::kAscii) {
    uint64_t least = 0;
    for (const PlyElement& e : header.elements) {
      const uint64_t row = MinRowBytes(e);
      if (row > 0 && e.count > (std::numeric_limits<uint64_t>::max() - least) / row) {
        ThrowInputError(where, "element '{}' count {} overflows", e.name, e.count);
      }
      least += row * e.count;
    }
    if (least > body.size()) {
      ThrowInputError(where,
                      "the header's element counts need at least {} bytes of data, the file "
                      "holds {}: it is truncated or a count is wrong",
                      least, body.size());
    }
  }

  PlyMesh out;
  TriangleMesh& mesh = out.mesh;
  BodyReader r(body, header.format, where);
  // Per-corner uvs of faces with a `texcoord` list (MeshLab), one per index.
  std::vector<glm::vec2> corner_uvs;
  std::vector<uint32_t> polygon;  // one face's indices
  std::vector<glm::vec2> uv;      // one face's corner uvs
  bool have_normals = false, have_uvs = false, have_corner_uvs = false;
  const uint64_t nverts = vertex->count;
  auto check_index = [&](int64_t index, const Place& what) {
    if (index < 0 || static_cast<uint64_t>(index) >= nverts) {
      ThrowInputError(where, "{}: vertex index {} is out of range ({} vertices)", what, index,
                      nverts);
    }
    return static_cast<uint32_t>(index);
  };

  for (const PlyElement& e : header.elements) {
    const uint64_t reserve = std::min<uint64_t>(e.count, r.remaining() / 2 + 1);
    if (e.name == "vertex") {
      // Slots: x y z nx ny nz u v.
      std::vector<int> slot(e.properties.size(), -1);
      const char* names[][8] = {{"x", "y", "z", "nx", "ny", "nz", "u", "v"},
                                {"x", "y", "z", "nx", "ny", "nz", "s", "t"},
                                {"x", "y", "z", "nx", "ny", "nz", "texture_u", "texture_v"},
                                {"x", "y", "z", "nx", "ny", "nz", "texture_s", "texture_t"}};
      bool seen[8] = {};
      for (size_t i = 0; i < e.properties.size(); ++i) {
        if (e.properties[i].is_list()) continue;
        for (const auto& set : names) {
          for (int s = 0; s < 8; ++s) {
            if (e.properties[i].name == set[s] && !seen[s]) {
              slot[i] = s;
              seen[s] = true;
            }
          }
        }
      }
      if (!seen[0] || !seen[1] || !seen[2]) {
        ThrowInputError(where, "element 'vertex' has no x, y and z properties");
      }
      have_normals = seen[3] && seen[4] && seen[5];
      have_uvs = seen[6] && seen[7];
      mesh.positions.reserve(reserve);
      if (have_normals) mesh.normals.reserve(reserve);
      if (have_uvs) mesh.uvs.reserve(reserve);
      for (uint64_t row = 0; row < e.count; ++row) {
        double v[8] = {};
        const Place what{"vertex", row};
        for (size_t i = 0; i < e.properties.size(); ++i) {
          const PlyProperty& p = e.properties[i];
          if (slot[i] < 0) {
            SkipProperty(r, p, what, where);
          } else {
            v[slot[i]] = r.Real(*ParseType(p.type), what);
          }
        }
        for (double x : v) {
          if (!std::isfinite(x) || std::abs(x) > 1e30) {
            ThrowInputError(where, "{}: a coordinate is not finite", what);
          }
        }
        mesh.positions.emplace_back(v[0], v[1], v[2]);
        if (have_normals) mesh.normals.emplace_back(v[3], v[4], v[5]);
        if (have_uvs) mesh.uvs.emplace_back(v[6], v[7]);
      }
    } else if (e.name == "face") {
      mesh.indices.reserve(3 * reserve);
      for (uint64_t row = 0; row < e.count; ++row) {
        const Place what{"face", row};
        int64_t corners = -1;
        for (const PlyProperty& p : e.properties) {
          if (IsIndexList(p) && corners < 0) {
            corners = r.Integer(*ParseType(p.count_type), what);
            if (corners < 3) {
              ThrowInputError(where, "{} has {} vertex indices (a face needs at least 3)", what,
                              corners);
            }
            if (static_cast<uint64_t>(corners) > r.remaining()) {
              ThrowInputError(where, "{}: {} indices run past the end of the file", what, corners);
            }
            polygon.resize(static_cast<size_t>(corners));
            for (auto& index : polygon) {
              index = check_index(r.Integer(*ParseType(p.type), what), what);
            }
            // A fan: n - 2 triangles in the polygon's own winding.
            for (size_t k = 1; k + 1 < polygon.size(); ++k) {
              mesh.indices.insert(mesh.indices.end(), {polygon[0], polygon[k], polygon[k + 1]});
            }
          } else if (p.is_list() && p.name == "texcoord" && corners >= 3) {
            const int64_t n = r.Integer(*ParseType(p.count_type), what);
            if (n != 2 * corners) {
              ThrowInputError(where, "{}: texcoord list of {} values for {} corners", what, n,
                              corners);
            }
            uv.resize(static_cast<size_t>(corners));
            for (auto& t : uv) {
              t.x = static_cast<float>(r.Real(*ParseType(p.type), what));
              t.y = static_cast<float>(r.Real(*ParseType(p.type), what));
              if (!std::isfinite(t.x) || !std::isfinite(t.y)) {
                ThrowInputError(where, "{}: a texture coordinate is not finite", what);
              }
            }
            // The fan's corners, as the indices above.
            corner_uvs.resize(mesh.indices.size() - 3 * (uv.size() - 2));
            for (size_t k = 1; k + 1 < uv.size(); ++k) {
              corner_uvs.insert(corner_uvs.end(), {uv[0], uv[k], uv[k + 1]});
            }
            have_corner_uvs = true;
          } else {
            SkipProperty(r, p, what, where);
          }
        }
        if (corners < 0) ThrowInputError(where, "element 'face' has no vertex_indices list");
      }
      out.faces = e.count;
    } else if (e.name == "tristrips") {
      for (uint64_t row = 0; row < e.count; ++row) {
        const Place what{"tristrips row", row};
        bool decoded = false;
        for (const PlyProperty& p : e.properties) {
          if (!IsIndexList(p) || decoded) {
            SkipProperty(r, p, what, where);
            continue;
          }
          decoded = true;
          const int64_t n = r.Integer(*ParseType(p.count_type), what);
          if (n < 0 || static_cast<uint64_t>(n) > r.remaining()) {
            ThrowInputError(where, "{}: a strip list of {} indices runs past the end of the file",
                            what, n);
          }
          // At most one triangle per index.
          CheckMemory(mesh.indices.size() * sizeof(uint32_t) + 3 * sizeof(uint32_t) * n, where,
                      fmt::format("the triangles of {} strip indices", n));
          int64_t run = 0;  // indices in the current strip
          uint32_t a = 0, b = 0;
          for (int64_t i = 0; i < n; ++i) {
            const int64_t index = r.Integer(*ParseType(p.type), what);
            if (index == -1) {
              if (run > 0) ++out.strips;
              run = 0;
              continue;
            }
            const uint32_t c = check_index(index, what);
            if (run >= 2) {
              // Odd triangles swap their first two: the strip keeps one winding.
              const uint32_t p0 = run % 2 == 0 ? a : b, p1 = run % 2 == 0 ? b : a;
              if (p0 != p1 && p1 != c && p0 != c) {
                mesh.indices.insert(mesh.indices.end(), {p0, p1, c});
                ++out.strip_triangles;
              } else {
                ++out.dropped_degenerate;
              }
            }
            a = b;
            b = c;
            ++run;
          }
          if (run > 0) ++out.strips;
        }
        if (!decoded) ThrowInputError(where, "element 'tristrips' has no vertex_indices list");
      }
    } else {
      for (uint64_t row = 0; row < e.count; ++row) {
        const Place what{e.name, row};
        for (const PlyProperty& p : e.properties) SkipProperty(r, p, what, where);
      }
    }
  }
  if (!r.AtEnd()) {
    ThrowInputError(where,
                    "{} bytes of data follow the last element the header declares: an element "
                    "count is wrong (the file holds more than its header says)",
                    r.remaining());
  }
  if (mesh.indices.empty()) {
    ThrowInputError(where, "no triangles ({} faces, {} strips)", out.faces, out.strips);
  }
  if (have_corner_uvs) {
    // Per-corner uvs: one vertex per corner (a seam may give a position two uvs).
    TriangleMesh split;
    split.positions.reserve(mesh.indices.size());
    corner_uvs.resize(mesh.indices.size());  // corners without texcoords: (0, 0)
    split.uvs = std::move(corner_uvs);
    if (have_normals) split.normals.reserve(mesh.indices.size());
    for (size_t k = 0; k < mesh.indices.size(); ++k) {
      split.positions.push_back(mesh.positions[mesh.indices[k]]);
      if (have_normals) split.normals.push_back(mesh.normals[mesh.indices[k]]);
      split.indices.push_back(static_cast<uint32_t>(k));
    }
    mesh = std::move(split);
  }
  for (const std::string& c : header.comments) {
    const std::vector<std::string_view> w = Words(c);
    if (w.size() >= 2 && w[0] == "TextureFile") {
      out.texture_file = c.substr(c.find("TextureFile") + std::string_view("TextureFile").size());
      out.texture_file.erase(0, out.texture_file.find_first_not_of(" \t"));
      break;
    }
  }
  mesh.Validate(where);
  return out;
}

PlyMesh ReadPly(const std::filesystem::path& path) {
  const std::string where = fmt::format("ReadPly: '{}'", path.string());
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowFileError("ReadPly", path, "cannot open");
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  // The body is held whole while the mesh is built.
  if (!ec) CheckMemory(size, where, "the file's data");
  return ReadPly(in, where);
}

}  // namespace core
