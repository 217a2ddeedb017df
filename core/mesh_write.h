// Writing meshes and point clouds for other tools (MeshLab, Blender, Open3D):
// binary little-endian PLY and Wavefront OBJ with its MTL. Streams first; the
// path overload writes atomically (core/atomic_file.h).
//
// PLY: `vertex` x y z (float), nx ny nz (float, if the mesh has normals),
// red green blue (uchar, if colours are given); `face` vertex_indices
// (uchar count, int indices), omitted for a point cloud.
// OBJ: `v x y z [r g b]` (colours in [0, 1]: the vertex-colour extension
// MeshLab, Blender and Open3D read), `vn`, faces `f a//a b//b c//c`
// (1-based), one material from NAME.mtl (white, so viewers show the vertex
// colours or the plain surface).
#pragma once

#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace core {

// `colours` is empty or one per vertex.
void WritePlyMesh(std::ostream& out, const TriangleMesh& mesh,
                  const std::vector<glm::u8vec3>& colours);
void WriteObjMesh(std::ostream& out, const TriangleMesh& mesh,
                  const std::vector<glm::u8vec3>& colours, const std::string& mtl_file);
void WriteObjMaterial(std::ostream& out);

// The bytes WriteMeshFile keeps in memory at most (none: it streams) plus the
// file's size, for messages and estimates.
uint64_t MeshFileBytes(const TriangleMesh& mesh, bool colours);

// `path` ends in .ply or .obj (then PATH_WITHOUT_EXT.mtl is written too);
// InputError naming the path otherwise, or when its folder does not exist.
void CheckMeshFilePath(std::string_view where, const std::filesystem::path& path,
                       bool allow_obj = true);
// Writes `path` (and the .mtl) atomically after CheckMeshFilePath.
void WriteMeshFile(const std::filesystem::path& path, const TriangleMesh& mesh,
                   const std::vector<glm::u8vec3>& colours);

}  // namespace core
