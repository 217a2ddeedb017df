#include "capture/mesh_counts.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/error.h"

namespace capture {
namespace {

constexpr const char* kWhere = "CountDeclaredFaces";

// The whitespace-separated tokens of `line` before a '#' comment.
std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream in(line.substr(0, line.find('#')));
  for (std::string t; in >> t;) tokens.push_back(t);
  return tokens;
}

bool ParseUint(const std::string& token, uint64_t& value) {
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

bool IsNumber(const std::string& token) {
  char* end = nullptr;
  std::strtod(token.c_str(), &end);
  return !token.empty() && end == token.c_str() + token.size();
}

}  // namespace

DeclaredFaces CountObjFaces(std::istream& in) {
  DeclaredFaces counts;
  uint64_t face_lines = 0;
  std::string line;
  while (std::getline(in, line)) {
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos || line[i] != 'f' || i + 1 >= line.size() ||
        (line[i + 1] != ' ' && line[i + 1] != '\t')) {
      continue;
    }
    uint64_t k = 0;
    for (i += 1; i < line.size();) {
      while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
      if (i >= line.size() || line[i] == '#') break;
      ++k;
      while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    }
    ++face_lines;
    counts.corners += k;
    if (k >= 3) counts.triangles += k - 2;
  }
  counts.what = fmt::format("its {} face lines", face_lines);
  return counts;
}

DeclaredFaces CountOffFaces(std::istream& in, const std::string& name) {
  // Tokens line by line, comments and blank lines skipped.
  std::string line;
  uint64_t line_number = 0;
  const auto next = [&](std::vector<std::string>& tokens) {
    while (std::getline(in, line)) {
      ++line_number;
      tokens = Tokens(line);
      if (!tokens.empty()) return true;
    }
    return false;
  };
  std::vector<std::string> t;
  if (!next(t)) core::ThrowFileError(kWhere, name, "empty OFF file");
  const std::string keyword = t[0];
  const bool known = keyword == "OFF" || keyword == "COFF" || keyword == "NOFF" ||
                     keyword == "CNOFF" || keyword == "STOFF" || keyword == "STCOFF" ||
                     keyword == "STNOFF" || keyword == "STCNOFF";
  if (!known) {
    core::ThrowFileError(kWhere, name,
                         "first keyword '{}' is not OFF, COFF, NOFF, CNOFF or STOFF (4OFF, nOFF "
                         "and binary OFF are not read)",
                         keyword.substr(0, 32));
  }
  // The counts may follow the keyword on its line.
  t.erase(t.begin());
  if (t.empty() && !next(t)) core::ThrowFileError(kWhere, name, "OFF header has no counts");
  uint64_t vertices = 0, faces = 0;
  if (t.size() < 2 || !ParseUint(t[0], vertices) || !ParseUint(t[1], faces)) {
    core::ThrowFileError(kWhere, name, "line {}: OFF counts '{}' are not 'VERTICES FACES [EDGES]'",
                         line_number, line.substr(0, 64));
  }
  uint64_t read_vertices = 0;
  while (read_vertices < vertices && next(t)) {
    if (t.size() < 3 || !IsNumber(t[0]) || !IsNumber(t[1]) || !IsNumber(t[2])) {
      core::ThrowFileError(kWhere, name, "line {}: vertex {} of {} is not three numbers",
                           line_number, read_vertices + 1, vertices);
    }
    ++read_vertices;
  }
  if (read_vertices < vertices) {
    core::ThrowFileError(kWhere, name,
                         "the OFF header declares {} vertices, the file holds {} (truncated?)",
                         vertices, read_vertices);
  }
  DeclaredFaces counts;
  uint64_t read_faces = 0;
  while (read_faces < faces && next(t)) {
    uint64_t k = 0;
    if (!ParseUint(t[0], k) || k >= t.size()) {
      core::ThrowFileError(kWhere, name,
                           "line {}: face {} of {} does not hold the corner count and that many "
                           "vertex indices",
                           line_number, read_faces + 1, faces);
    }
    ++read_faces;
    counts.corners += k;
    if (k >= 3) counts.triangles += k - 2;
  }
  if (read_faces < faces) {
    core::ThrowFileError(kWhere, name,
                         "the OFF header declares {} faces, the file holds {} (truncated?)", faces,
                         read_faces);
  }
  counts.what = fmt::format("its OFF header's {} faces", faces);
  return counts;
}

DeclaredFaces CountStlFaces(std::istream& in, const std::string& name) {
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) core::ThrowFileError(kWhere, name, "cannot measure the STL file");
  const uint64_t bytes = static_cast<uint64_t>(size);
  std::string head(std::min<uint64_t>(bytes, 84), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  uint64_t count = 0;
  if (head.size() == 84) {
    uint32_t n = 0;
    std::memcpy(&n, head.data() + 80, 4);  // little endian, as the format says (x86 here)
    count = n;
  }
  DeclaredFaces counts;
  if (head.size() == 84 && bytes == 84 + 50 * count) {
    counts.triangles = count;
    counts.corners = 3 * count;
    counts.what = fmt::format("its binary STL header's {} triangles", count);
    return counts;
  }
  const size_t first = head.find_first_not_of(" \t\r\n");
  if (first == std::string::npos || head.compare(first, 5, "solid") != 0) {
    if (head.size() < 84) {
      core::ThrowFileError(kWhere, name,
                           "{} bytes: shorter than a binary STL header (84 bytes) and not ASCII "
                           "STL (no 'solid')",
                           bytes);
    }
    core::ThrowFileError(kWhere, name,
                         "the binary STL header declares {} triangles ({} bytes), the file has {} "
                         "bytes ({})",
                         count, 84 + 50 * count, bytes,
                         bytes < 84 + 50 * count ? "truncated" : "extra bytes after the last");
  }
  // ASCII: facet / outer loop / 3 x vertex / endloop / endfacet, in solids.
  in.clear();
  in.seekg(0, std::ios::beg);
  std::string line;
  uint64_t line_number = 0, facets = 0, open_solids = 0, vertices_in_facet = 0;
  bool in_facet = false;
  while (std::getline(in, line)) {
    ++line_number;
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    if (key == "solid") {
      ++open_solids;
    } else if (key == "endsolid") {
      if (open_solids == 0 || in_facet) {
        core::ThrowFileError(kWhere, name,
                             "line {}: 'endsolid' without an open solid or inside "
                             "facet {}",
                             line_number, facets);
      }
      --open_solids;
    } else if (key == "facet") {
      if (in_facet || open_solids == 0) {
        core::ThrowFileError(kWhere, name, "line {}: 'facet' inside facet {} or outside a solid",
                             line_number, facets);
      }
      in_facet = true;
      vertices_in_facet = 0;
      ++facets;
    } else if (key == "vertex") {
      std::string x, y, z;
      if (!in_facet || !(words >> x >> y >> z) || !IsNumber(x) || !IsNumber(y) || !IsNumber(z)) {
        core::ThrowFileError(kWhere, name,
                             "line {}: a vertex outside a facet or without three numbers",
                             line_number);
      }
      ++vertices_in_facet;
    } else if (key == "endfacet") {
      if (!in_facet || vertices_in_facet != 3) {
        core::ThrowFileError(kWhere, name, "line {}: facet {} has {} vertices, not 3", line_number,
                             facets, vertices_in_facet);
      }
      in_facet = false;
    }
  }
  if (in_facet || open_solids > 0) {
    core::ThrowFileError(kWhere, name, "ASCII STL ends inside {} after {} facets (truncated?)",
                         in_facet ? fmt::format("facet {}", facets) : std::string("a solid"),
                         facets - (in_facet ? 1 : 0));
  }
  counts.triangles = facets;
  counts.corners = 3 * facets;
  counts.what = fmt::format("its {} ASCII STL facets", facets);
  return counts;
}

std::optional<DeclaredFaces> CountDeclaredFaces(std::istream& in, const std::string& extension,
                                                const std::string& name) {
  if (extension == ".obj") return CountObjFaces(in);
  if (extension == ".off") return CountOffFaces(in, name);
  if (extension == ".stl") return CountStlFaces(in, name);
  return std::nullopt;
}

}  // namespace capture
