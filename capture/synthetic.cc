#include "capture/synthetic.h"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>

#include "capture/mesh_counts.h"
#include "capture/sensor_model.h"
#include "core/check.h"
#include "core/error.h"
#include "core/image_io.h"
#include "core/memory_budget.h"
#include "core/ply_io.h"
#include "core/projection.h"
#include "render/gl/gpu_mesh.h"
#include "render/gl/texture_upload.h"
#include "render/passes/mesh_pass.h"
#include "render/passes/pass.h"

namespace capture {
namespace fs = std::filesystem;

// ---------------------------------------------------------------- meshes ----

namespace {

constexpr const char* kLoadWhere = "LoadSceneMesh";

// A mesh as a file gives it, before textures: per-vertex normals and uvs
// (uvs (0, 0) where the file has none), the textures its materials name in
// the order the file uses them.
struct FileMesh {
  core::TriangleMesh mesh;
  bool has_uvs = false;
  std::vector<std::string> material_textures;
};

std::string Lowercase(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

FileMesh LoadPly(const fs::path& path) {
  core::PlyMesh ply = core::ReadPly(path);
  FileMesh out;
  out.mesh = std::move(ply.mesh);
  out.has_uvs = !out.mesh.uvs.empty();
  // The image convention (row 0 at the top), as assimp's aiProcess_FlipUVs.
  for (glm::vec2& uv : out.mesh.uvs) uv.y = 1.0f - uv.y;
  if (!out.has_uvs) out.mesh.uvs.assign(out.mesh.positions.size(), glm::vec2(0));
  if (out.mesh.normals.empty()) core::SetAreaWeightedNormals(out.mesh);
  if (!ply.texture_file.empty()) out.material_textures.push_back(ply.texture_file);
  if (ply.strips > 0) {
    spdlog::info("{}: '{}': {} triangles from {} triangle strips ({} zero-area joins dropped)",
                 kLoadWhere, path.string(), ply.strip_triangles, ply.strips,
                 ply.dropped_degenerate);
  }
  return out;
}

FileMesh LoadWithAssimp(const fs::path& path) {
  const std::string extension = Lowercase(path.extension().string());
  const uint64_t file_bytes = fs::file_size(path);
  // What the file declares (OBJ face lines, an OFF header, an STL count or
  // facets), counted first: a file that contradicts itself is refused here.
  std::optional<DeclaredFaces> declared;
  {
    std::ifstream in(path, std::ios::binary);
    declared = CountDeclaredFaces(in, extension, path.string());
  }
  // assimp's importer holds the file, its own per-corner copy of positions,
  // normals and uvs (3 floats each) and faces, and post-processing copies: an
  // estimate of 4x the file plus 96 bytes per corner where corners are known
  // (OBJ, OFF, STL), else 16x the file (binary formats are denser than their meshes).
  const uint64_t estimate = declared ? 4 * file_bytes + 96 * declared->corners : 16 * file_bytes;
  core::CheckMemory(estimate, fmt::format("{}: '{}'", kLoadWhere, path.string()),
                    declared ? fmt::format("loading the mesh ({} face corners)", declared->corners)
                             : std::string("loading the mesh"));
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                         aiProcess_FlipUVs | aiProcess_SortByPType);
  if (!scene || !scene->mRootNode || scene->mNumMeshes == 0) {
    core::ThrowFileError(kLoadWhere, path, "cannot load mesh: {}", importer.GetErrorString());
  }
  FileMesh out;
  out.has_uvs = true;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    out.has_uvs = out.has_uvs && mesh->HasTextureCoords(0);
    if (mesh->mMaterialIndex < scene->mNumMaterials) {
      aiString tex;
      if (scene->mMaterials[mesh->mMaterialIndex]->GetTexture(aiTextureType_DIFFUSE, 0, &tex) ==
              AI_SUCCESS &&
          tex.length > 0 && tex.C_Str()[0] != '*') {
        const std::string name = tex.C_Str();
        if (std::find(out.material_textures.begin(), out.material_textures.end(), name) ==
            out.material_textures.end()) {
          out.material_textures.push_back(name);
        }
      }
    }
    const uint32_t base = static_cast<uint32_t>(out.mesh.positions.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      out.mesh.positions.emplace_back(p.x, p.y, p.z);
      const aiVector3D n = mesh->HasNormals() ? mesh->mNormals[v] : aiVector3D(0, 0, 1);
      out.mesh.normals.emplace_back(n.x, n.y, n.z);
      if (mesh->HasTextureCoords(0)) {
        out.mesh.uvs.emplace_back(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y);
      } else {
        out.mesh.uvs.emplace_back(0, 0);
      }
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (int k = 0; k < 3; ++k) out.mesh.indices.push_back(base + face.mIndices[k]);
    }
  }
  if (out.mesh.indices.empty()) core::ThrowFileError(kLoadWhere, path, "no triangles");
  // What the file declares against what was loaded: a face lost by the
  // importer is a wrong picture of the object, never a quiet success.
  if (declared && declared->triangles != out.mesh.triangle_count()) {
    core::ThrowFileError(kLoadWhere, path,
                         "{} declare {} triangles, the importer loaded {}: the file is "
                         "malformed or not read right",
                         declared->what, declared->triangles, out.mesh.triangle_count());
  }
  // Degenerate normals (isolated vertices): any unit vector keeps GL happy.
  for (auto& n : out.mesh.normals) {
    const float len = glm::length(n);
    n = std::isfinite(len) && len > 0 ? n / len : glm::vec3(0, 0, 1);
  }
  return out;
}

// A texture path as a material writes it, made usable here: backslashes
// (Windows exporters: ".\x.jpg") become separators, a leading "./" goes.
fs::path NormaliseTexturePath(std::string name) {
  std::replace(name.begin(), name.end(), '\\', '/');
  while (name.rfind("./", 0) == 0) name.erase(0, 2);
  return fs::path(name);
}

// RGBA8 from any 8-bit image.
core::Image8 ToRgba(const core::Image8& image) {
  core::Image8 rgba(image.width(), image.height(), 4, 255);
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < 3; ++c) {
        rgba.at(x, y, c) = image.at(x, y, image.channels() >= 3 ? c : 0);
      }
    }
  }
  return rgba;
}

// The texture of a mesh without --texture: each material texture in turn
// (as written, then its file name beside the mesh), else "<stem>_texture.png",
// "<stem>.png", "<stem>.jpg" beside the mesh. A material texture that cannot
// be read is a warning (the geometry is still right); finding nothing is
// logged with every path tried.
core::Image8 FindTexture(const fs::path& path, const FileMesh& file) {
  const fs::path dir = path.parent_path();
  std::vector<std::string> tried;
  core::Image8 found;
  std::string found_name;
  for (const std::string& name : file.material_textures) {
    const fs::path relative = NormaliseTexturePath(name);
    std::vector<fs::path> candidates = {dir / relative};
    if (relative.has_parent_path()) candidates.push_back(dir / relative.filename());
    bool loaded = false;
    for (const fs::path& candidate : candidates) {
      tried.push_back(candidate.string());
      if (!fs::exists(candidate)) continue;
      try {
        core::Image8 image = core::ReadImage<uint8_t>(candidate);
        if (found.empty()) {
          found = ToRgba(image);
          found_name = candidate.string();
        }
        loaded = true;
        break;
      } catch (const core::InputError& e) {
        spdlog::warn("{}: '{}': material texture '{}' is unreadable ({}); not used", kLoadWhere,
                     path.string(), candidate.string(), e.what());
        loaded = true;  // warned already
        break;
      }
    }
    if (!loaded) {
      std::string paths;
      for (const fs::path& c : candidates)
        paths += (paths.empty() ? "'" : ", '") + c.string() + "'";
      spdlog::warn("{}: '{}': material texture '{}' not found (tried {}); not used", kLoadWhere,
                   path.string(), name, paths);
    }
  }
  if (!found.empty()) {
    if (file.material_textures.size() > 1) {
      spdlog::warn("{}: '{}': {} material textures; only '{}' is used, for the whole mesh",
                   kLoadWhere, path.string(), file.material_textures.size(), found_name);
    }
    return found;
  }
  for (const char* suffix : {"_texture.png", ".png", ".jpg"}) {
    const fs::path guess = dir / (path.stem().string() + suffix);
    tried.push_back(guess.string());
    if (fs::exists(guess)) return ToRgba(core::ReadImage<uint8_t>(guess));
  }
  spdlog::info("{}: '{}': no texture found (tried '{}'); untextured", kLoadWhere, path.string(),
               fmt::join(tried, "', '"));
  return {};
}

}  // namespace

SceneMesh LoadSceneMesh(const fs::path& path, const fs::path& texture_path, MeshTextures textures) {
  constexpr const char* kWhere = kLoadWhere;
  if (fs::is_directory(path)) core::ThrowFileError(kWhere, path, "is a folder, not a mesh file");
  if (!fs::exists(path)) core::ThrowFileError(kWhere, path, "file does not exist");
  if (!fs::is_regular_file(path)) core::ThrowFileError(kWhere, path, "not a regular file");
  FileMesh file =
      Lowercase(path.extension().string()) == ".ply" ? LoadPly(path) : LoadWithAssimp(path);
  SceneMesh out;
  out.source = path.string();
  out.mesh = std::move(file.mesh);
  out.mesh.Validate(fmt::format("{}: '{}'", kWhere, path.string()));
  // Captures and --truth-mesh frame the mesh by its bounds: they must be a
  // box the float renderer can resolve (dataset.h's limits).
  glm::vec3 lo, hi;
  out.mesh.Bounds(lo, hi);
  Bounds bounds{glm::dvec3(lo), glm::dvec3(hi)};
  const glm::dvec3 extent = bounds.extent();
  const double largest_side = std::max({extent.x, extent.y, extent.z});
  const double pad = 0.5 * std::max(largest_side, kDatasetLimits.min_extent);
  if (!(largest_side >= kDatasetLimits.min_extent)) {
    core::ThrowFileError(kWhere, path,
                         "mesh has no extent (all vertices within {:.3g} of each other)",
                         largest_side);
  }
  // A flat mesh is fine (a plane); only its overall size is checked.
  CheckBounds({bounds.centre() - pad, bounds.centre() + pad},
              fmt::format("{}: '{}'", kWhere, path.string()));

  if (textures == MeshTextures::kSkip) return out;
  if (!texture_path.empty()) {
    // Named by the user: it must load, and it wins over the materials'.
    if (!file.has_uvs) {
      spdlog::warn("{}: '{}' has no UVs; texture '{}' ignored", kWhere, path.string(),
                   texture_path.string());
    } else {
      out.texture = ToRgba(core::ReadImage<uint8_t>(texture_path));
    }
    return out;
  }
  if (file.has_uvs) out.texture = FindTexture(path, file);
  return out;
}

std::vector<std::string> ShapeNames() { return {"sphere", "torus", "box", "cup"}; }

SceneMesh MakeShapeScene(std::string_view name) {
  SceneMesh out;
  out.source = fmt::format("shape:{}", name);
  if (name == "sphere") {
    out.mesh = core::MakeSphere(1.0f, 256, 512);
  } else if (name == "torus") {
    out.mesh = core::MakeTorus(1.0f, 0.4f, 512, 256);
  } else if (name == "box") {
    out.mesh = core::MakeBox({1.0f, 0.7f, 0.5f});
  } else if (name == "cup") {
    out.mesh = core::MakeCup(1.0f, 1.2f, 0.12f, 512);
  } else if (name == "mug") {
    out.mesh = core::MakeMug(1.0f, 1.2f, 0.12f, 0.35f, 0.08f, 512);
  } else {
    core::ThrowInputError("MakeShapeScene",
                          "unknown shape '{}' (expected sphere, torus, box, cup or mug)", name);
  }
  return out;
}

// ------------------------------------------------------------------ rigs ----

RigSpec RigSpec::Parse(std::string_view text) {
  constexpr const char* kWhere = "RigSpec::Parse";
  if (text == "cube") return {Kind::kCube, 6};
  const auto colon = text.find(':');
  if (colon == std::string_view::npos) {
    core::ThrowInputError(kWhere, "rig '{}' is not cube, ring:N or sphere:N", text);
  }
  const std::string_view kind = text.substr(0, colon), count = text.substr(colon + 1);
  int n = 0;
  const auto [ptr, ec] = std::from_chars(count.data(), count.data() + count.size(), n);
  if (ec != std::errc() || ptr != count.data() + count.size() || n < 1 || n > 1000) {
    core::ThrowInputError(kWhere, "rig '{}': N must be an integer in 1..1000", text);
  }
  if (kind == "ring") return {Kind::kRing, n};
  if (kind == "sphere") return {Kind::kSphere, n};
  core::ThrowInputError(kWhere, "rig '{}' is not cube, ring:N or sphere:N", text);
}

std::string RigSpec::ToString() const {
  switch (kind) {
    case Kind::kCube:
      return "cube";
    case Kind::kRing:
      return fmt::format("ring:{}", count);
    case Kind::kSphere:
      return fmt::format("sphere:{}", count);
  }
  return {};
}

void CaptureOptions::Check() const {
  constexpr const char* kWhere = "CaptureOptions";
  if (size < 16 || size > 8192) core::ThrowInputError(kWhere, "size {} is outside 16..8192", size);
  RigSpec::Parse(rig);
  if (!(fov_deg > 1 && fov_deg < 170))
    core::ThrowInputError(kWhere, "fov {} is outside 1..170 degrees", fov_deg);
  if (!(margin >= 0 && margin < 1))
    core::ThrowInputError(kWhere, "margin {} is outside [0, 1)", margin);
  if (!(std::abs(ring_elevation_deg) < 89))
    core::ThrowInputError(kWhere, "ring elevation must be within +-89 degrees");
  if (!(glm::length(up) > 0)) core::ThrowInputError(kWhere, "up vector is zero");
  if (background != "black" && background != "noise") {
    core::ThrowInputError(kWhere, "background '{}' is not black or noise", background);
  }
  // The spec's syntax and ranges now, before any view is rendered (lengths
  // are resolved against the object's size in CaptureDataset).
  if (!noise.empty()) ParseSensorModel(noise, 1.0, 1.0);
}

std::vector<RigView> MakeRig(const RigSpec& rig, const Bounds& bounds,
                             const CaptureOptions& options) {
  options.Check();
  const glm::dvec3 centre = bounds.centre();
  const glm::dvec3 extent = bounds.extent();
  const int size = options.size;
  std::vector<RigView> views;
  const glm::dvec3 up = glm::normalize(options.up);
  // Two axes spanning the plane perpendicular to `up`.
  glm::dvec3 a = glm::cross(up, glm::dvec3(1, 0, 0));
  if (glm::length(a) < 1e-6) a = glm::cross(up, glm::dvec3(0, 1, 0));
  a = glm::normalize(a);
  const glm::dvec3 b = glm::cross(a, up);

  if (rig.kind == RigSpec::Kind::kCube) {
    // Kautz-Seidel 2001, sec. 4: depth maps on the six faces of the object's
    // bounding cube, orthographic, each looking inwards; the image plane is
    // the cube face, so depth is the distance from that face.
    const double half = 0.5 * std::max({extent.x, extent.y, extent.z, 1e-9}) * (1 + options.margin);
    const double scale = size / (2 * half);  // pixels per scene unit
    const glm::dvec3 axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    const char* names[6] = {"cube_px", "cube_nx", "cube_py", "cube_ny", "cube_pz", "cube_nz"};
    // Image up: `up` for the side faces; looking down / up along it, the
    // axis after up's main one (y up: -z / +z).
    int main_axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(up[k]) > std::abs(up[main_axis])) main_axis = k;
    glm::dvec3 front(0.0);
    front[(main_axis + 1) % 3] = up[main_axis] < 0 ? -1 : 1;
    for (int f = 0; f < 6; ++f) {
      const glm::dvec3 eye = centre + half * axes[f];
      const double along = glm::dot(axes[f], up);
      const glm::dvec3 face_up = std::abs(along) > 0.5 ? (along > 0 ? -front : front) : up;
      RigView view;
      view.name = names[f];
      view.camera = Camera::Orthographic(size, size, scale, scale, size / 2.0, size / 2.0);
      view.cam_from_world = LookAt(eye, centre, face_up);
      view.near = 0;
      view.far = 2 * half;
      views.push_back(view);
    }
    return views;
  }

  const double radius = 0.5 * glm::length(extent) * (1 + options.margin);  // bounding sphere
  const double half_fov = options.fov_deg * std::numbers::pi / 360;
  const double distance = std::max(radius, 1e-9) / std::sin(half_fov);
  const double f = (size / 2.0) / std::tan(half_fov);
  const int n = rig.count;
  for (int i = 0; i < n; ++i) {
    glm::dvec3 dir;
    if (rig.kind == RigSpec::Kind::kRing) {
      const double phi = 2 * std::numbers::pi * i / n;
      const double e = options.ring_elevation_deg * std::numbers::pi / 180;
      dir = std::cos(e) * (std::cos(phi) * a + std::sin(phi) * b) + std::sin(e) * up;
    } else {
      // Fibonacci sphere: even coverage, no point exactly at a pole.
      const double y = 1 - (2.0 * i + 1) / n;
      const double r = std::sqrt(std::max(0.0, 1 - y * y));
      const double phi = i * std::numbers::pi * (3 - std::sqrt(5.0));
      dir = r * std::cos(phi) * a + y * up + r * std::sin(phi) * b;
    }
    RigView view;
    view.name = fmt::format("{}_{:03d}", rig.kind == RigSpec::Kind::kRing ? "ring" : "sphere", i);
    view.camera = Camera::Pinhole(size, size, f, f, size / 2.0, size / 2.0);
    view.cam_from_world = LookAt(centre + distance * dir, centre, up);
    view.near = std::max(distance - radius, 1e-3 * distance);
    view.far = distance + radius;
    views.push_back(view);
  }
  return views;
}

// -------------------------------------------------------------- rendering ----

namespace {

// The scene on the GPU, uploaded once per capture.
class GpuScene {
 public:
  explicit GpuScene(const SceneMesh& scene) : mesh_(scene.mesh) {
    if (!scene.texture.empty()) {
      texture_ = render::UploadRgba8Texture(scene.texture, render::TextureWrap::kRepeat,
                                            render::TextureWrap::kRepeat);
    }
  }
  const render::GpuMesh& mesh() const { return mesh_; }
  const render::Texture* texture() const { return texture_ ? &texture_ : nullptr; }

 private:
  render::GpuMesh mesh_;
  render::Texture texture_;
};

// Deterministic value noise in [0, 1]: lattice values from an integer hash,
// smoothstep-interpolated, periodic in x with period `period_x` cells.
double LatticeValue(uint32_t x, uint32_t y, uint32_t seed) {
  uint32_t h = x * 0x8da6b343u ^ y * 0xd8163841u ^ seed * 0xcb1ab31fu;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (h & 0xffffff) / double(0xffffff);
}

double ValueNoise(double x, double y, int period_x, uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  const double sx = tx * tx * (3 - 2 * tx), sy = ty * ty * (3 - 2 * ty);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  auto v = [&](int64_t cx, int64_t cy) {
    const int64_t wrapped = ((cx % period_x) + period_x) % period_x;
    return LatticeValue(static_cast<uint32_t>(wrapped), static_cast<uint32_t>(cy), seed);
  };
  const double a = v(ix, iy) + sx * (v(ix + 1, iy) - v(ix, iy));
  const double b = v(ix, iy + 1) + sx * (v(ix + 1, iy + 1) - v(ix, iy + 1));
  return a + sy * (b - a);
}

}  // namespace

core::Image8 NoiseTexture(int width, int height, uint32_t seed) {
  IBR_CHECK(width >= 64 && height >= 1);
  core::Image8 tex(width, height, 4, 255);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0, weight = 0, amplitude = 1;
        for (int octave = 0; octave < 5; ++octave) {
          const int cells = (width / 64) << octave;  // across the width
          const double scale = static_cast<double>(cells) / width;
          sum += amplitude * ValueNoise((x + 0.5) * scale, (y + 0.5) * scale, cells,
                                        seed * 101u + 17u * c + octave);
          weight += amplitude;
          amplitude *= 0.85;
        }
        const double v = std::clamp((sum / weight - 0.5) * 3.5 + 0.5, 0.0, 1.0);
        tex.at(x, y, c) = static_cast<uint8_t>(std::lround(255 * v));
      }
    }
  }
  return tex;
}

namespace {

// The noise backdrop on the GPU: a unit sphere scaled and placed per capture.
class Backdrop {
 public:
  Backdrop() : mesh_(core::MakeSphere(1.0f, 128, 256)) {
    // 2048 x 1024: from the ring cameras a view spans ~70 degrees of the
    // backdrop, so its cells are ~5..80 px, blobs at the scales SIFT detects.
    texture_ = render::UploadRgba8Texture(NoiseTexture(2048, 1024, 0), render::TextureWrap::kRepeat,
                                          render::TextureWrap::kClampToEdge);
  }
  const render::GpuMesh& mesh() const { return mesh_; }
  const render::Texture& texture() const { return texture_; }

 private:
  render::GpuMesh mesh_;
  render::Texture texture_;
};

// Where the backdrop sits: centre, radius, poles along `up`.
struct BackdropPlacement {
  glm::dvec3 centre{0.0};
  double radius = 0;
  glm::dvec3 up{0, 1, 0};
};

BackdropPlacement PlaceBackdrop(const Bounds& bounds, const std::vector<RigView>& views,
                                const glm::dvec3& up) {
  BackdropPlacement p;
  p.centre = bounds.centre();
  double farthest = 0.5 * glm::length(bounds.extent());
  for (const RigView& v : views)
    farthest = std::max(farthest, glm::length(v.cam_from_world.Centre() - p.centre));
  p.radius = 2 * std::max(farthest, 1e-6);
  p.up = glm::normalize(up);
  return p;
}

// The backdrop's colour as seen from `view` (flat, unshaded texture).
core::Image8 RenderBackdrop(render::ProgramCache& programs, const Backdrop& backdrop,
                            const BackdropPlacement& place, const RigView& view) {
  const Camera& cam = view.camera;
  const double d = glm::length(view.cam_from_world.Centre() - place.centre);
  const double near = std::max(place.radius - d, 1e-3 * place.radius) * 0.5,
               far = (place.radius + d) * 1.5;
  render::ViewSetup setup;
  setup.cam_from_world = view.cam_from_world.ToMat4();
  setup.orthographic = cam.orthographic();
  setup.clip_from_cam = cam.orthographic()
                            ? core::ClipFromCamOrthographic(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                            cam.width, cam.height, 0, far)
                            : core::ClipFromCamPerspective(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                           cam.width, cam.height, near, far);
  // Object frame: the unit sphere's poles (z) along `up`.
  glm::dvec3 a = glm::cross(place.up, glm::dvec3(1, 0, 0));
  if (glm::length(a) < 1e-6) a = glm::cross(place.up, glm::dvec3(0, 1, 0));
  a = glm::normalize(a);
  const glm::dvec3 b = glm::cross(place.up, a);
  glm::dmat4 world_from_object(1.0);
  world_from_object[0] = glm::dvec4(place.radius * a, 0);
  world_from_object[1] = glm::dvec4(place.radius * b, 0);
  world_from_object[2] = glm::dvec4(place.radius * place.up, 0);
  world_from_object[3] = glm::dvec4(place.centre, 1);
  render::MeshPassOptions pass;
  pass.texture = &backdrop.texture();
  pass.shade = false;
  pass.world_from_object = glm::mat4(world_from_object);
  return render::RenderMesh(programs, backdrop.mesh(), setup, cam.width, cam.height, pass).color;
}

CapturedView Render(render::ProgramCache& programs, const GpuScene& gpu, const RigView& view,
                    const CaptureOptions& options) {
  const Camera& cam = view.camera;
  render::ViewSetup setup;
  setup.cam_from_world = view.cam_from_world.ToMat4();
  setup.orthographic = cam.orthographic();
  setup.clip_from_cam =
      cam.orthographic() ? core::ClipFromCamOrthographic(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                         cam.width, cam.height, view.near, view.far)
                         : core::ClipFromCamPerspective(cam.fx(), cam.fy(), cam.cx(), cam.cy(),
                                                        cam.width, cam.height, view.near, view.far);
  render::MeshPassOptions pass;
  pass.base_color = options.base_color;
  pass.texture = gpu.texture();
  pass.shade = options.shade;
  const render::Frame frame =
      render::RenderMesh(programs, gpu.mesh(), setup, cam.width, cam.height, pass);

  CapturedView out;
  out.color = core::Image8(cam.width, cam.height, 3);
  out.depth = core::ImageF(cam.width, cam.height, 1);
  out.mask = core::Image8(cam.width, cam.height, 1);
  out.normal = core::ImageF(cam.width, cam.height, 3);
  const glm::dmat3& r = view.cam_from_world.rotation;
  for (int row = 0; row < cam.height; ++row) {
    for (int col = 0; col < cam.width; ++col) {
      for (int c = 0; c < 3; ++c) out.color.at(col, row, c) = frame.color.at(col, row, c);
      const bool covered = frame.color.at(col, row, 3) == 255;
      const float depth = frame.depth.at(col, row);
      if (!covered || !(depth > 0)) continue;
      out.mask.at(col, row) = 255;
      out.depth.at(col, row) = depth;
      glm::dvec3 n(frame.normal.at(col, row, 0), frame.normal.at(col, row, 1),
                   frame.normal.at(col, row, 2));
      const double len = glm::length(n);
      if (!(len > 0)) continue;
      n /= len;
      // Face the camera: against the viewing ray.
      const glm::dvec3 ray =
          cam.orthographic() ? glm::dvec3(0, 0, 1) : cam.UnprojectPixel(col, row, 1.0);
      if (glm::dot(r * n, ray) > 0) n = -n;
      for (int c = 0; c < 3; ++c) out.normal.at(col, row, c) = static_cast<float>(n[c]);
    }
  }
  return out;
}

Bounds MeshBounds(const core::TriangleMesh& mesh) {
  glm::vec3 lo, hi;
  mesh.Bounds(lo, hi);
  return {glm::dvec3(lo), glm::dvec3(hi)};
}

}  // namespace

namespace {
// The object's colour over the backdrop where the object does not cover.
void Composite(CapturedView& view, const core::Image8& backdrop) {
  for (int row = 0; row < view.color.height(); ++row) {
    for (int col = 0; col < view.color.width(); ++col) {
      if (view.mask.at(col, row)) continue;
      for (int c = 0; c < 3; ++c) view.color.at(col, row, c) = backdrop.at(col, row, c);
    }
  }
}
}  // namespace

CapturedView RenderView(render::ProgramCache& programs, const SceneMesh& scene, const RigView& view,
                        const CaptureOptions& options) {
  options.Check();
  const GpuScene gpu(scene);
  CapturedView out = Render(programs, gpu, view, options);
  if (options.background == "noise") {
    const Backdrop backdrop;
    Composite(out, RenderBackdrop(programs, backdrop,
                                  PlaceBackdrop(MeshBounds(scene.mesh), {view}, options.up), view));
  }
  return out;
}

uint64_t CaptureBytes(const SceneMesh& scene, const CaptureOptions& options) {
  // Per pixel: the frame target on the GPU (llvmpipe keeps it in system
  // memory), its readback (RGBA8 4 + camera z 4 + normal 3 floats 12), the
  // captured view (colour 3 + depth 4 + mask 1 + normal 12) and the backdrop's
  // colour (4). Views are written one at a time, so one view's worth is held.
  const uint64_t pixels = uint64_t(options.size) * uint64_t(options.size);
  const uint64_t per_pixel = uint64_t(render::FrameBytesPerPixel()) + 20 + 20 + 4;
  // The mesh on the GPU (position, normal, uv, indices) and its texture.
  const uint64_t mesh = scene.mesh.positions.size() * 32 + scene.mesh.indices.size() * 4 +
                        scene.texture.pixel_count() * 4;
  return pixels * per_pixel + mesh;
}

Dataset CaptureDataset(render::ProgramCache& programs, const SceneMesh& scene,
                       const CaptureOptions& options, const fs::path& out,
                       const std::function<void(int, int, const std::string&)>& progress) {
  options.Check();
  const Bounds bounds = MeshBounds(scene.mesh);
  const std::vector<RigView> views = MakeRig(RigSpec::Parse(options.rig), bounds, options);
  core::CheckMemory(CaptureBytes(scene, options), "ibr capture",
                    fmt::format("a capture of '{}' at {}x{} px ({} views, one at a time)",
                                scene.source, options.size, options.size, views.size()));
  const GpuScene gpu(scene);
  std::optional<Backdrop> backdrop;
  if (options.background == "noise") backdrop.emplace();
  const BackdropPlacement place = PlaceBackdrop(bounds, views, options.up);
  DatasetWriter writer(out);
  size_t covered_views = 0;
  writer.SetBounds(bounds);
  writer.SetUp(options.up);  // what orbits, the viewer and exports turn about
  std::optional<SensorModel> sensor;
  if (!options.noise.empty()) {
    // `%` lengths are of the object's diagonal; a quadratic model's
    // reference depth is the cameras' mean distance to its centre.
    double z_ref = 0;
    for (const RigView& view : views)
      z_ref += glm::length(view.cam_from_world.Centre() - bounds.centre()) / views.size();
    sensor = ParseSensorModel(options.noise, glm::length(bounds.extent()), z_ref);
    spdlog::info("capture: sensor model ({} = {:.4g} scene units across): {}",
                 "the object's diagonal", glm::length(bounds.extent()), sensor->Describe());
    writer.SetDepthNoise(*sensor);
  }
  for (size_t i = 0; i < views.size(); ++i) {
    const RigView& view = views[i];
    CapturedView captured = Render(programs, gpu, view, options);
    if (backdrop) Composite(captured, RenderBackdrop(programs, *backdrop, place, view));
    if (sensor) {
      ApplySensorModel(*sensor, view.camera, view.cam_from_world, view.near, view.far, i,
                       captured.depth, captured.mask, captured.normal);
    }
    int64_t covered = 0;
    for (uint8_t m : captured.mask.values()) covered += m != 0;
    if (covered == 0) {
      spdlog::warn("capture: view {} of '{}' is empty (the mesh covers no pixel)", view.name,
                   scene.source);
    }
    covered_views += covered > 0;
    const int camera_id = writer.AddCamera(view.camera);
    writer.AddView(view.name, camera_id, view.cam_from_world, captured.color, captured.depth,
                   captured.mask, captured.normal);
    if (progress) progress(static_cast<int>(i) + 1, static_cast<int>(views.size()), view.name);
  }
  // Nothing seen from any camera: the mesh or the rig is wrong, and a dataset
  // of empty views would only render as nothing later.
  if (covered_views == 0) {
    core::ThrowInputError("ibr capture",
                          "every one of the {} views of '{}' is empty: the mesh covers no pixel "
                          "from any camera ({} triangles)",
                          views.size(), scene.source, scene.mesh.triangle_count());
  }
  writer.Commit();
  return writer.dataset();
}

}  // namespace capture
