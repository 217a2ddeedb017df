// What a mesh file declares about its faces, counted from its own bytes
// before assimp reads it (capture::LoadSceneMesh): the triangles its faces
// make, checked afterwards against what the importer loaded, and the face
// corners for the memory estimate. A file that contradicts itself (an OFF
// header or a binary STL count promising more faces than follow, an ASCII
// STL cut inside a facet or before its `endsolid`) is an InputError naming
// the file, so a truncated mesh is never loaded as a smaller object.
#pragma once

#include <cstdint>
#include <istream>
#include <optional>
#include <string>

namespace capture {

struct DeclaredFaces {
  uint64_t triangles = 0;  // a face of k >= 3 corners gives k - 2
  uint64_t corners = 0;    // face corners (indices), for the memory estimate
  std::string what;        // how the file declares them, for messages ("its 12 face lines")
};

// OBJ: the `f` lines (points and lines give no triangle). Never throws.
DeclaredFaces CountObjFaces(std::istream& in);
// OFF (also COFF, NOFF, CNOFF, STOFF): the header's vertex and face counts
// against the lines that follow; each face line's corner count against its
// indices. InputError naming `name` on a mismatch or a malformed header.
DeclaredFaces CountOffFaces(std::istream& in, const std::string& name);
// STL: binary when the size is exactly 84 + 50 x the header's count, else
// ASCII when it starts with `solid` (facets of 3 vertices each, every solid
// closed by `endsolid`), else a binary file whose size contradicts its
// count. InputError naming `name` on any mismatch.
DeclaredFaces CountStlFaces(std::istream& in, const std::string& name);

// By extension (lower case, with the dot): ".obj", ".off", ".stl"; nullopt
// for formats whose files declare no count here.
std::optional<DeclaredFaces> CountDeclaredFaces(std::istream& in, const std::string& extension,
                                                const std::string& name);

}  // namespace capture
