#include "core/mesh_write.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"

namespace core {
namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLY writer copies little-endian values as they are in memory");

template <typename T>
void Put(std::string& buffer, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  buffer.append(bytes, sizeof(T));
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

void WritePlyMesh(std::ostream& out, const TriangleMesh& mesh,
                  const std::vector<glm::u8vec3>& colours) {
  IBR_CHECK(colours.empty() || colours.size() == mesh.positions.size());
  const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.normals.empty();
  out << "ply\nformat binary_little_endian 1.0\ncomment written by ibr\n";
  out << "element vertex " << mesh.positions.size() << "\n";
  out << "property float x\nproperty float y\nproperty float z\n";
  if (normals) out << "property float nx\nproperty float ny\nproperty float nz\n";
  if (!colours.empty()) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (!mesh.indices.empty()) {
    out << "element face " << mesh.triangle_count() << "\n";
    out << "property list uchar int vertex_indices\n";
  }
  out << "end_header\n";
  // In chunks, so a large mesh never needs a second copy in memory.
  std::string buffer;
  auto flush = [&](bool force) {
    if (force || buffer.size() > (1u << 20)) {
      out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      buffer.clear();
    }
  };
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) Put(buffer, mesh.positions[i][k]);
    if (normals)
      for (int k = 0; k < 3; ++k) Put(buffer, mesh.normals[i][k]);
    if (!colours.empty())
      for (int k = 0; k < 3; ++k) Put(buffer, colours[i][k]);
    flush(false);
  }
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    Put(buffer, static_cast<uint8_t>(3));
    for (int k = 0; k < 3; ++k) Put(buffer, static_cast<int32_t>(mesh.indices[t + k]));
    flush(false);
  }
  flush(true);
}

void WriteObjMesh(std::ostream& out, const TriangleMesh& mesh,
                  const std::vector<glm::u8vec3>& colours, const std::string& mtl_file) {
  IBR_CHECK(colours.empty() || colours.size() == mesh.positions.size());
  const bool normals = mesh.normals.size() == mesh.positions.size() && !mesh.normals.empty();
  std::string buffer = fmt::format("# written by ibr\nmtllib {}\n", mtl_file);
  auto flush = [&](bool force) {
    if (force || buffer.size() > (1u << 20)) {
      out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      buffer.clear();
    }
  };
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3& p = mesh.positions[i];
    if (colours.empty()) {
      fmt::format_to(std::back_inserter(buffer), "v {} {} {}\n", p.x, p.y, p.z);
    } else {
      const glm::u8vec3& c = colours[i];
      fmt::format_to(std::back_inserter(buffer), "v {} {} {} {:.6g} {:.6g} {:.6g}\n", p.x, p.y, p.z,
                     c.r / 255.0, c.g / 255.0, c.b / 255.0);
    }
    flush(false);
  }
  if (normals) {
    for (const glm::vec3& n : mesh.normals) {
      fmt::format_to(std::back_inserter(buffer), "vn {} {} {}\n", n.x, n.y, n.z);
      flush(false);
    }
  }
  buffer += "usemtl ibr_object\n";
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t] + 1, b = mesh.indices[t + 1] + 1,
                   c = mesh.indices[t + 2] + 1;
    if (normals) {
      fmt::format_to(std::back_inserter(buffer), "f {0}//{0} {1}//{1} {2}//{2}\n", a, b, c);
    } else {
      fmt::format_to(std::back_inserter(buffer), "f {} {} {}\n", a, b, c);
    }
    flush(false);
  }
  flush(true);
}

void WriteObjMaterial(std::ostream& out) {
  out << "# written by ibr: white, so the vertex colours (or the plain surface) show\n"
         "newmtl ibr_object\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\n";
}

uint64_t MeshFileBytes(const TriangleMesh& mesh, bool colours) {
  return mesh.positions.size() * (24 + (colours ? 3 : 0)) + mesh.triangle_count() * 13;
}

void CheckMeshFilePath(std::string_view where, const std::filesystem::path& path, bool allow_obj) {
  const std::string ext = Lower(path.extension().string());
  if (ext != ".ply" && !(allow_obj && ext == ".obj")) {
    ThrowFileError(where, path, "unknown mesh format '{}' ({})", ext,
                   allow_obj ? ".ply or .obj" : ".ply");
  }
  const std::filesystem::path parent =
      path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(parent, ec)) {
    ThrowFileError(where, path, "folder '{}' does not exist", parent.string());
  }
  if (std::filesystem::is_directory(path, ec)) ThrowFileError(where, path, "is a folder");
  CheckNotAnInput(where, path);
}

void WriteMeshFile(const std::filesystem::path& path, const TriangleMesh& mesh,
                   const std::vector<glm::u8vec3>& colours) {
  CheckMeshFilePath("WriteMeshFile", path);
  if (Lower(path.extension().string()) == ".ply") {
    AtomicWriteStream(path, [&](std::ostream& out) { WritePlyMesh(out, mesh, colours); });
    return;
  }
  std::filesystem::path mtl = path;
  mtl.replace_extension(".mtl");
  CheckNotAnInput("WriteMeshFile", mtl);
  // The material first: an OBJ never names a material file that is missing.
  AtomicWriteStream(mtl, [&](std::ostream& out) { WriteObjMaterial(out); });
  AtomicWriteStream(
      path, [&](std::ostream& out) { WriteObjMesh(out, mesh, colours, mtl.filename().string()); });
}

}  // namespace core
