// PLY meshes (Turk's polygon file format, the Stanford and scanner exchange
// format): ascii, binary_little_endian and binary_big_endian, every scalar
// type of the format. Our own reader, not assimp's: assimp 5.2 turns a
// `tristrips` element into one triangle (issue 34), and a mesh whose faces
// are lost must be refused, never rendered as nearly nothing.
//
// What is decoded:
// - `vertex`: x y z (required), nx ny nz, and a uv pair named u v, s t,
//   texture_u texture_v or texture_s texture_t (all optional);
// - `face`: the list `vertex_indices` (or `vertex_index`), polygons fanned
//   into n - 2 triangles; MeshLab's per-corner `texcoord` list;
// - `tristrips`: the list `vertex_indices` of one or more rows, -1 ending a
//   strip; a strip's k-th triangle (k from 0) is (s[k], s[k+1], s[k+2]) for
//   even k and (s[k+1], s[k], s[k+2]) for odd k, so every triangle keeps the
//   first one's winding; triangles repeating an index (the zero-area joins
//   strippers insert) are dropped;
// - any other element is skipped, unless it carries a vertex index list
//   (e.g. a scanner's `range_grid`): then the file is refused, since faces
//   would be lost.
// What is refused (core::InputError naming the file and the place): a header
// that is not PLY, an unknown type, a body shorter than its element counts
// (a count that lies upwards) or data after the last declared element (a
// count that lies downwards), an index out of range, a face of fewer than 3
// vertices, a non-finite coordinate, no triangles at all.
#pragma once

#include <cstdint>
#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace core {

struct PlyProperty {
  std::string name;
  std::string type;        // scalar type, or the list's item type
  std::string count_type;  // list length type; empty for a scalar
  bool is_list() const { return !count_type.empty(); }
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian };
  Format format = Format::kAscii;
  std::vector<PlyElement> elements;
  std::vector<std::string> comments;  // text after "comment " / "obj_info "
  const PlyElement* Find(const std::string& name) const;
};

// Reads the header up to and including "end_header\n"; `in` is left at the
// first body byte. `where` names the source for messages.
PlyHeader ReadPlyHeader(std::istream& in, const std::string& where);

// The memory the mesh of `header` takes once read (positions, normals, uvs
// and indices, one triangle per face at least), for core::CheckMemory before
// the body is read.
uint64_t EstimatePlyMeshBytes(const PlyHeader& header);

struct PlyMesh {
  TriangleMesh mesh;                // normals only if the file has them; uvs if it has any
  std::string texture_file;         // MeshLab's "comment TextureFile NAME"; empty if none
  uint64_t faces = 0;               // rows of the `face` element
  uint64_t strips = 0;              // strips (runs between -1) of the `tristrips` element
  uint64_t strip_triangles = 0;     // triangles decoded from the strips
  uint64_t dropped_degenerate = 0;  // zero-area strip joins dropped
};

// Reads a whole PLY file (header and body) from `in`. Checks the memory
// budget (core/memory_budget.h) on the header's counts before allocating.
PlyMesh ReadPly(std::istream& in, const std::string& where);
// Opens `path` (binary) and reads it; messages name the path.
PlyMesh ReadPly(const std::filesystem::path& path);

}  // namespace core
