#include "render/passes/deform_pass.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "core/error.h"
#include "core/projection.h"
#include "render/gl/uniform.h"

namespace render {

DeformImplicit DeformImplicitFromName(const std::string& name) {
  return core::EnumFromName(kDeformImplicitNames, name, "DeformImplicitFromName", "implicit");
}

std::string DeformImplicitName(DeformImplicit implicit) {
  return std::string(core::EnumToName(kDeformImplicitNames, implicit));
}

void DepthCube::Check(const std::string& where) const {
  if (faces.size() != 6)
    core::ThrowInputError(where, "a depth cube has 6 faces, not {}", faces.size());
  const int n = faces[0].depth.width();
  for (const DepthCubeFace& f : faces) {
    if (f.depth.width() != n || f.depth.height() != n || f.depth.channels() != 1 || n < 2) {
      core::ThrowInputError(where, "depth cube faces must be one square size >= 2, got {}x{}x{}",
                            f.depth.width(), f.depth.height(), f.depth.channels());
    }
  }
  if (!std::isfinite(far) || !(far > 0) || !std::isfinite(texel) || !(texel > 0))
    core::ThrowInputError(where, "depth cube far {} / texel {} must be finite and > 0", far, texel);
}

int64_t DepthCube::Bytes() const {
  int64_t bytes = 0;
  for (const DepthCubeFace& f : faces)
    bytes += static_cast<int64_t>(f.depth.width()) * f.depth.height() * 4;
  return bytes;
}

void DeformPassOptions::Check() const {
  if (!draw_mesh && !draw_rays)
    core::ThrowInputError("DeformPassOptions", "draw_mesh and draw_rays both off: nothing to draw");
  if (!std::isfinite(thickness) || !(thickness > 0)) {
    core::ThrowInputError("DeformPassOptions", "thickness {} must be finite and > 0", thickness);
  }
  if (!std::isfinite(step_voxels) || step_voxels < 0.01f || step_voxels > 64) {
    core::ThrowInputError("DeformPassOptions", "step {} voxels outside [0.01, 64]", step_voxels);
  }
  if (!std::isfinite(seam_band_voxels) || !(seam_band_voxels > 0) || seam_band_voxels > 64) {
    core::ThrowInputError("DeformPassOptions", "seam band {} voxels outside (0, 64]",
                          seam_band_voxels);
  }
  for (float c :
       {base_color.r, base_color.g, base_color.b, cut_color.r, cut_color.g, cut_color.b}) {
    if (!(c >= 0 && c <= 1))
      core::ThrowInputError("DeformPassOptions", "colour component {} outside [0, 1]", c);
  }
  RayCore().Check();
}

RayCoreOptions DeformPassOptions::RayCore() const {
  RayCoreOptions core;
  core.max_steps = max_steps;
  core.refine_steps = refine_steps;
  core.step_policy = step_policy;
  core.threshold = threshold;
  core.fine_step_scale = 0.25f;
  return core;
}

std::vector<std::string> DeformPassOptions::Defines() const {
  std::vector<std::string> defines = RayCoreDefines(RayCore());
  switch (cut) {
    case CutMode::kNone:
      break;
    case CutMode::kHollow:
      defines.push_back("CUT_HOLLOW");
      break;
    case CutMode::kSolid:
      defines.push_back("CUT_SOLID");
      break;
    case CutMode::kThick:
      defines.push_back("CUT_THICK");
      break;
  }
  if (skip_empty && cut != CutMode::kNone) defines.push_back("SKIP_EMPTY");
  if (solid_search && (cut == CutMode::kSolid || cut == CutMode::kThick))
    defines.push_back("SOLID_SEARCH");
  if (skip_object && implicit == DeformImplicit::kSdf) defines.push_back("SKIP_OBJECT");
  if (implicit == DeformImplicit::kDepthCube) defines.push_back("IMPLICIT_DEPTH_CUBE");
  defines.push_back("RAY_STAGE");
  return defines;
}

std::vector<std::string> DeformPassOptions::MeshDefines() const {
  std::vector<std::string> defines = {"MESH_STAGE"};
  if (!seam_blend) return defines;
  defines.push_back("SEAM_BLEND");
  if (implicit == DeformImplicit::kDepthCube) defines.push_back("IMPLICIT_DEPTH_CUBE");
  return defines;
}

namespace {

// The outcome bits, shared by both stages' shaders.
std::vector<std::string> BitDefines(bool orthographic) {
  std::vector<std::string> defines = {fmt::format("DEFORM_CUT_FACE_BIT {}u", kDeformCutFaceBit),
                                      fmt::format("DEFORM_MESH_BIT {}u", kDeformMeshBit),
                                      fmt::format("DEFORM_REJECTED_SHIFT {}", kDeformRejectedShift),
                                      fmt::format("DEFORM_REJECTED_MAX {}", kDeformRejectedMax),
                                      fmt::format("DEFORM_SAMPLES_SHIFT {}", kDeformSamplesShift)};
  if (orthographic) defines.push_back("ORTHOGRAPHIC");
  return defines;
}

Texture Upload3D(GLenum format, GLenum channels, glm::ivec3 size, const float* data) {
  Texture texture = Texture::Create3DWithData(format, size, channels, GL_FLOAT, data);
  texture.SetLinearFilter();
  return texture;
}

// The bricks of the Lipschitz grid over the deformation box (the distance-
// field skip reads a bound of the warp's |I + J| per brick).
constexpr int kLipschitzBricks = 8;

// Per brick of a kLipschitzBricks^3 grid over the box and per axis, the
// largest difference of each channel (D's x, y, z and the alpha) along that
// axis over the brick's cells and every piece: the trilinear interpolant's
// partial derivatives are convex combinations of a cell's four edge
// differences along the axis, so these bound them (per texel). One scan of
// the texture serves both Lipschitz bounds below.
using BrickDifferences = std::array<glm::dvec4, 3>;  // [axis][channel]
std::vector<BrickDifferences> MaxDifferencesPerBrick(const core::DeformationTexture& texture) {
  const int n = texture.resolution, b = kLipschitzBricks;
  size_t piece = 0;
  auto d = [&](int i, int j, int k) {
    const float* t = &texture.rgba[(((piece * n + k) * n + j) * n + i) * 4];
    return glm::dvec4(t[0], t[1], t[2], t[3]);
  };
  // The brick of cell c (cells 0 .. n - 2 per axis).
  auto brick = [&](int c) { return std::min(c * b / std::max(n - 1, 1), b - 1); };
  std::vector<BrickDifferences> bricks(static_cast<size_t>(b) * b * b,
                                       {glm::dvec4(0.0), glm::dvec4(0.0), glm::dvec4(0.0)});
  for (piece = 0; piece < static_cast<size_t>(texture.pieces); ++piece)
    for (int k = 0; k + 1 < n; ++k)
      for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
          BrickDifferences& m =
              bricks[(static_cast<size_t>(brick(k)) * b + brick(j)) * b + brick(i)];
          for (int s = 0; s < 2; ++s)
            for (int t = 0; t < 2; ++t) {
              m[0] = glm::max(m[0], glm::abs(d(i + 1, j + s, k + t) - d(i, j + s, k + t)));
              m[1] = glm::max(m[1], glm::abs(d(i + s, j + 1, k + t) - d(i + s, j, k + t)));
              m[2] = glm::max(m[2], glm::abs(d(i + s, j + t, k + 1) - d(i + s, j + t, k)));
            }
        }
  return bricks;
}

// Upper bound of |grad A| in object units over the texture's trilinear
// interpolant: per axis the largest difference of A (over every piece: the
// skip reads the flap's mask too), mapped to object units through
// ||M^-T|| <= Frobenius norm of M^-1.
float AlphaLipschitz(const std::vector<BrickDifferences>& bricks, int resolution,
                     const core::Placement& placement) {
  glm::dvec3 g(0.0);
  for (const BrickDifferences& m : bricks) g = glm::max(g, glm::dvec3(m[0].w, m[1].w, m[2].w));
  g *= double(resolution - 1);  // per box unit
  glm::dmat3 inv = glm::inverse(placement.Linear());
  double frobenius = 0.0;
  for (int c = 0; c < 3; ++c) frobenius += glm::dot(inv[c], inv[c]);
  return static_cast<float>(std::max(1e-6, glm::length(g) * std::sqrt(frobenius)));
}

// An upper bound of the largest singular value of m: the square root of
// Gershgorin's bound of the largest eigenvalue of m^T m (its largest
// absolute row sum), exact for a similarity. For a matrix of non-negative
// entries bounding |J| entrywise it bounds ||J||_2 too (the norm is monotone
// in the entries' magnitudes).
double SpectralNormBound(const glm::dmat3& m) {
  const glm::dmat3 g = glm::transpose(m) * m;
  double largest = 0.0;
  for (int r = 0; r < 3; ++r)
    largest = std::max(largest, std::abs(g[0][r]) + std::abs(g[1][r]) + std::abs(g[2][r]));
  return std::sqrt(largest);
}

// Local upper bounds of |I + M J_D M^-1| (spectral norm, object units) over
// the trilinear interpolants of every piece's D, per brick: the brick's
// difference bounds of D (MaxDifferencesPerBrick) as a matrix, its norm and
// ||M||, ||M^-1|| (SpectralNormBound each); then each brick takes the largest
// bound of its 3^3 neighbourhood, so it holds for any segment that starts in
// the brick and is shorter than one brick (WarpSkipCap). A global bound was
// useless for the bench's twist (25: the angle falls from 2 rad to 0 over
// 0.15 of the box at its rigid radius) while most of the box moves rigidly or
// not at all.
std::vector<float> WarpLipschitzGrid(const std::vector<BrickDifferences>& bricks, int resolution,
                                     const core::Placement& placement) {
  const int b = kLipschitzBricks;
  const glm::dmat3 m = placement.Linear();
  const double scale =
      SpectralNormBound(m) * double(resolution - 1) * SpectralNormBound(glm::inverse(m));
  std::vector<float> local(bricks.size()), dilated(bricks.size());
  for (size_t i = 0; i < bricks.size(); ++i) {
    glm::dmat3 e;  // e[axis][component]
    for (int axis = 0; axis < 3; ++axis) e[axis] = glm::dvec3(bricks[i][axis]);
    const double bound = 1.0 + scale * SpectralNormBound(e);
    local[i] = static_cast<float>(std::isfinite(bound) ? std::min(bound, 1e30) : 1e30);
  }
  for (int k = 0; k < b; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < b; ++i) {
        float v = 1.0f;
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int x = i + di, y = j + dj, z = k + dk;
              if (x < 0 || y < 0 || z < 0 || x >= b || y >= b || z >= b) continue;
              v = std::max(v, local[(static_cast<size_t>(z) * b + y) * b + x]);
            }
        dilated[(static_cast<size_t>(k) * b + j) * b + i] = v;
      }
  return dilated;
}

// The longest object-space segment that stays within one brick of the
// Lipschitz grid in box coordinates: 1 / kLipschitzBricks box units, through
// ||M^-1||.
float WarpSkipCap(const core::Placement& placement) {
  return static_cast<float>(1.0 / kLipschitzBricks /
                            SpectralNormBound(glm::inverse(placement.Linear())));
}

}  // namespace

DeformPass::DeformPass(ProgramCache& programs, const DeformInputs& inputs,
                       const DeformPassOptions& options)
    : programs_(programs), options_(options), placement_(inputs.placement) {
  options_.Check();
  placement_.Check();
  if (!inputs.deformation || inputs.deformation->resolution < 2) {
    core::ThrowInputError("DeformPass", "no deformation texture");
  }
  // The deformation texture is checked before anything is uploaded.
  const core::DeformationTexture& d = *inputs.deformation;
  if (d.pieces < 1 || d.pieces > 2 ||
      d.rgba.size() !=
          static_cast<size_t>(d.pieces) * d.resolution * d.resolution * d.resolution * 4) {
    core::ThrowInputError("DeformPass", "deformation texture of {} floats for {} piece(s) of {}^3",
                          d.rgba.size(), d.pieces, d.resolution);
  }
  if (d.pieces == 2 && d.alpha_components.size() != d.rgba.size()) {
    core::ThrowInputError("DeformPass", "{} alpha components for {} texture floats",
                          d.alpha_components.size(), d.rgba.size());
  }
  if (options_.implicit == DeformImplicit::kDepthCube) {
    if (!inputs.depth_cube) core::ThrowInputError("DeformPass", "no depth cube");
    UploadDepthCube(*inputs.depth_cube);
  } else {
    if (!inputs.sdf || inputs.sdf->values.empty())
      core::ThrowInputError("DeformPass", "no distance field");
    const core::DistanceField& sdf = *inputs.sdf;
    sdf_ = Upload3D(GL_R32F, GL_RED, sdf.size, sdf.values.data());
    sdf_origin_ = glm::vec3(sdf.origin);
    sdf_spacing_ = static_cast<float>(sdf.spacing);
    sdf_size_ = sdf.size;
    sdf_margin_ = static_cast<float>(sdf.LookupOverestimate());
  }
  deformation_resolution_ = d.resolution;
  deformation_ = Upload3D(GL_RGBA32F, GL_RGBA, glm::ivec3(d.resolution), d.rgba.data());
  if (d.pieces == 2) {
    const size_t half = d.rgba.size() / 2;
    deformation_flap_ =
        Upload3D(GL_RGBA32F, GL_RGBA, glm::ivec3(d.resolution), d.rgba.data() + half);
    alpha_components_ =
        Upload3D(GL_RGBA32F, GL_RGBA, glm::ivec3(d.resolution), d.alpha_components.data());
    alpha_components_flap_ =
        Upload3D(GL_RGBA32F, GL_RGBA, glm::ivec3(d.resolution), d.alpha_components.data() + half);
  }
  {
    const std::vector<BrickDifferences> bricks = MaxDifferencesPerBrick(d);
    alpha_lipschitz_ = AlphaLipschitz(bricks, d.resolution, placement_);
    const std::vector<float> grid = WarpLipschitzGrid(bricks, d.resolution, placement_);
    warp_lipschitz_ = Texture::Create3DWithData(GL_R32F, glm::ivec3(kLipschitzBricks), GL_RED,
                                                GL_FLOAT, grid.data());
    warp_skip_cap_ = WarpSkipCap(placement_);
  }
  if (inputs.mesh && options_.draw_mesh) {
    inputs.mesh->Validate("DeformPass");
    // Classify the triangles against the box once (the box is fixed per
    // pass): drawing every triangle as six clipped pieces made stage 1 cost
    // six times the mesh's vertex work.
    const core::TriangleMesh& mesh = *inputs.mesh;
    const glm::dmat4 box_from_object = placement_.BoxFromObject();
    core::TriangleMesh outside = mesh, crossing = mesh;
    outside.indices.clear();
    crossing.indices.clear();
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      glm::dvec3 u[3];
      for (int k = 0; k < 3; ++k) {
        u[k] = glm::dvec3(box_from_object *
                          glm::dvec4(glm::dvec3(mesh.positions[mesh.indices[3 * t + k]]), 1.0));
      }
      bool out = false, in = true;
      for (int a = 0; a < 3; ++a) {
        out |= (u[0][a] < 0 && u[1][a] < 0 && u[2][a] < 0) ||
               (u[0][a] > 1 && u[1][a] > 1 && u[2][a] > 1);
        for (int k = 0; k < 3; ++k) in &= u[k][a] > 0 && u[k][a] < 1;
      }
      if (in && !out) continue;
      core::TriangleMesh& to = out ? outside : crossing;
      to.indices.insert(to.indices.end(), mesh.indices.begin() + 3 * t,
                        mesh.indices.begin() + 3 * t + 3);
    }
    cull_back_faces_ = options_.cull_back_faces && core::IsClosedOutward(mesh);
    glm::vec3 lo, hi;
    mesh.Bounds(lo, hi);
    mesh_bounds_ = {glm::dvec3(lo), glm::dvec3(hi)};
    if (!outside.indices.empty()) {
      if (cull_back_faces_) {
        mesh_outside_.emplace(GpuMesh::Clustered(outside));
      } else {
        mesh_outside_.emplace(outside);
      }
    }
    if (!crossing.indices.empty()) mesh_crossing_.emplace(crossing);
  }
  // The unit box as 12 triangles (36 corners, positions in box units).
  static const int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                   {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  std::vector<glm::vec3> corners;
  for (const auto& f : kFaces) {
    for (int c : {f[0], f[1], f[2], f[0], f[2], f[3]})
      corners.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  }
  box_vbo_ = Buffer::CreateWithData(corners.data(),
                                    static_cast<GLsizeiptr>(corners.size() * sizeof(glm::vec3)));
  box_vao_ = VertexArray::Create();
  glVertexArrayVertexBuffer(box_vao_.id(), 0, box_vbo_.id(), 0, sizeof(glm::vec3));
  glEnableVertexArrayAttrib(box_vao_.id(), kPositionLocation);
  glVertexArrayAttribFormat(box_vao_.id(), kPositionLocation, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(box_vao_.id(), kPositionLocation, 0);
}

void DeformPass::UploadDepthCube(const DepthCube& cube) {
  cube.Check("DeformPass");
  const int n = cube.faces[0].depth.width();
  sdf_ = Texture::Create(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(sdf_.id(), 1, GL_R32F, n, n, 6);
  std::vector<float> layer(static_cast<size_t>(n) * n);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (int i = 0; i < 6; ++i) {
    const DepthCubeFace& face = cube.faces[i];
    // Nothing seen: the surface at the far face (the face only says empty),
    // except a one-texel ring around the silhouette, which takes the nearest
    // depth of its seen neighbours. Without the ring the bilinear blend of
    // the last seen texel and the far face carves up to a texel inside the
    // silhouette, shifting the faces another map sees head-on (a box's sides:
    // 1.5 texels mean depth error at 64 px maps); with it the face's solid
    // extends past its silhouette instead, where the faces that see that
    // region carve it (intersection).
    const auto seen = [&](int x, int y) {
      const float d = face.depth.at(x, y);
      return std::isfinite(d) && d > 0;
    };
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        float d = face.depth.at(x, y);
        if (!seen(x, y)) {
          d = static_cast<float>(cube.far);
          for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = x + dx, yy = y + dy;
              if (xx >= 0 && yy >= 0 && xx < n && yy < n && seen(xx, yy))
                d = std::min(d, face.depth.at(xx, yy));
            }
          }
        }
        layer[static_cast<size_t>(y) * n + x] = d;
      }
    }
    glTextureSubImage3D(sdf_.id(), 0, 0, 0, i, n, n, 1, GL_RED, GL_FLOAT, layer.data());
    // (u, v) pixels -> (s, t) texture coordinates (row v = texel row v).
    glm::dmat4 tex_from_map(1.0);
    tex_from_map[0][0] = tex_from_map[1][1] = 1.0 / n;
    cube_from_object_.push_back(glm::mat4(tex_from_map * face.map_from_object));
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  sdf_.SetLinearFilter();
  for (GLenum p : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
    glTextureParameteri(sdf_.id(), p, GL_CLAMP_TO_EDGE);
  sdf_spacing_ = static_cast<float>(cube.texel);
}

namespace {

// Corner c (bit k: hi on axis k) of the box [lo, hi].
glm::dvec3 BoxCorner(const glm::dvec3& lo, const glm::dvec3& hi, int c) {
  return {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z};
}

// Whether every corner of `box` is strictly in front of the near plane of
// clip_from_world (w > 0 and z > -w, GL's clip volume).
bool InFrontOfNearPlane(const glm::dmat4& clip_from_world, const core::Box3d& box) {
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 v = clip_from_world * glm::dvec4(BoxCorner(box.lo, box.hi, c), 1.0);
    if (!(v.w > 0.0) || !(v.z + v.w > 1e-9 * v.w)) return false;
  }
  return true;
}

// The pixel rectangle (x, y, width, height) holding the projection of the
// box [lo, hi] through clip_from_local, one pixel of margin, clipped to the
// target; the whole target when a corner is not in front of the eye.
glm::ivec4 ScreenRect(const glm::dmat4& clip_from_local, const glm::dvec3& lo, const glm::dvec3& hi,
                      int width, int height) {
  glm::dvec2 a(std::numeric_limits<double>::infinity()), b(-a);
  for (int c = 0; c < 8; ++c) {
    const glm::dvec4 v = clip_from_local * glm::dvec4(BoxCorner(lo, hi, c), 1.0);
    if (!(v.w > 0.0)) return {0, 0, width, height};
    const glm::dvec2 px = (glm::dvec2(v) / v.w * 0.5 + 0.5) * glm::dvec2(width, height);
    a = glm::min(a, px);
    b = glm::max(b, px);
  }
  const glm::dvec2 size(width, height);
  const glm::ivec2 lo_px(glm::clamp(glm::floor(a) - 1.0, glm::dvec2(0.0), size));
  const glm::ivec2 hi_px(glm::clamp(glm::ceil(b) + 1.0, glm::dvec2(0.0), size));
  return {lo_px.x, lo_px.y, hi_px.x - lo_px.x, hi_px.y - lo_px.y};
}

// Stage 1: shaders/passes/deform_mesh.vert.glsl + deform.frag.glsl (MESH_STAGE).
struct DeformMeshUniforms {
  explicit DeformMeshUniforms(const Program& p)
      : box_from_object(p, "u_box_from_object"),
        base_color(p, "u_base_color"),
        piece(p, "u_piece"),
        object_from_box(p, "u_object_from_box"),
        cube_from_object(p, "u_cube_from_object"),
        sdf_origin(p, "u_sdf_origin"),
        sdf_size(p, "u_sdf_size"),
        sdf_spacing(p, "u_sdf_spacing"),
        seam_band(p, "u_seam_band"),
        sdf(p, "u_sdf") {}
  Uniform<glm::mat4> box_from_object;
  Uniform<glm::vec4> base_color;
  Uniform<int> piece;  // which of the box complement's six pieces; -1: no clipping
  // SEAM_BLEND only: the implicit, as the ray stage reads it.
  Uniform<glm::mat4> object_from_box;
  UniformArray<glm::mat4> cube_from_object;  // depth cube only
  Uniform<glm::vec3> sdf_origin;             // distance field only
  Uniform<glm::vec3> sdf_size;               // distance field only
  Uniform<float> sdf_spacing;
  Uniform<float> seam_band;  // object units
  Uniform<int> sdf;          // texture unit
};

// Stage 2: shaders/passes/deform_box.vert.glsl + deform.frag.glsl.
struct DeformBoxUniforms {
  explicit DeformBoxUniforms(const Program& p)
      : world_from_cam(p, "u_world_from_cam"),
        clip_z(p, "u_clip_z"),
        object_from_box(p, "u_object_from_box"),
        box_from_object(p, "u_box_from_object"),
        cube_from_object(p, "u_cube_from_object"),
        sdf_origin(p, "u_sdf_origin"),
        sdf_size(p, "u_sdf_size"),
        sdf_spacing(p, "u_sdf_spacing"),
        deform_resolution(p, "u_deform_resolution"),
        step(p, "u_step"),
        thickness(p, "u_thickness"),
        alpha_lipschitz(p, "u_alpha_lipschitz"),
        warp_skip_cap(p, "u_warp_skip_cap"),
        warp_lipschitz(p, "u_warp_lipschitz"),
        sdf_margin(p, "u_sdf_margin"),
        base_color(p, "u_base_color"),
        cut_color(p, "u_cut_color"),
        sdf(p, "u_sdf"),
        deformation(p, "u_deformation"),
        deformation_flap(p, "u_deformation_flap"),
        alpha_components(p, "u_alpha_components"),
        alpha_components_flap(p, "u_alpha_components_flap") {}
  Uniform<glm::mat4> world_from_cam;
  Uniform<glm::vec2> clip_z;
  Uniform<glm::mat4> object_from_box;
  Uniform<glm::mat4> box_from_object;
  UniformArray<glm::mat4> cube_from_object;  // depth cube only
  Uniform<glm::vec3> sdf_origin;             // distance field only
  Uniform<glm::vec3> sdf_size;               // distance field only
  Uniform<float> sdf_spacing;
  Uniform<float> deform_resolution;
  Uniform<float> step;
  Uniform<float> thickness;
  Uniform<float> alpha_lipschitz;
  Uniform<float> warp_skip_cap;
  Uniform<int> warp_lipschitz;  // texture units: this and the samplers below
  Uniform<float> sdf_margin;
  Uniform<glm::vec4> base_color;
  Uniform<glm::vec4> cut_color;
  Uniform<int> sdf;
  Uniform<int> deformation;
  Uniform<int> deformation_flap;
  Uniform<int> alpha_components;
  Uniform<int> alpha_components_flap;
};

}  // namespace

void DeformPass::Draw(const RenderTarget& target, const ViewSetup& view) {
  BindOutcomeImage(target);  // both stages OR their bits (pass.h)
  last_culled_back_faces_ = false;
  last_culled_clusters_ = 0;
  const glm::mat4 object_from_box(placement_.object_from_box);
  const glm::mat4 box_from_object(placement_.BoxFromObject());
  const std::vector<std::string> view_defines = BitDefines(view.orthographic);
  // The implicit's uniforms, as both stages' programs read it (the mesh
  // stage with seam blending).
  const auto set_implicit = [&](const auto& u) {
    if (options_.implicit == DeformImplicit::kDepthCube) {
      u.cube_from_object.Set(cube_from_object_);
    } else {
      u.sdf_origin.Set(sdf_origin_);
      u.sdf_size.Set(glm::vec3(sdf_size_));
    }
    u.sdf_spacing.Set(sdf_spacing_);
  };

  // Stage 1: the mesh outside the box, as six convex pieces of the box's
  // complement (gl_ClipDistance keeps an intersection of half-spaces).
  if (mesh_outside_ || mesh_crossing_) {
    ProgramDesc desc{.vertex = "passes/deform_mesh.vert.glsl",
                     .fragment = "passes/deform.frag.glsl"};
    desc.defines = view_defines;
    const std::vector<std::string> mesh_defines = options_.MeshDefines();
    desc.defines.insert(desc.defines.end(), mesh_defines.begin(), mesh_defines.end());
    const Program& program = programs_.Get(desc);
    UseProgram(target, program, view);
    const auto& u = program.Typed<DeformMeshUniforms>();
    u.box_from_object.Set(box_from_object);
    u.base_color.Set(options_.base_color);
    if (options_.seam_blend) {
      u.object_from_box.Set(object_from_box);
      set_implicit(u);
      u.seam_band.Set(options_.seam_band_voxels * sdf_spacing_);
      u.sdf.Set(0);
      glBindTextureUnit(0, sdf_.id());
    }
    // A closed, outward mesh wholly in front of the near plane: each ray
    // meets a front face before any back face, so back faces are hidden
    // except where the front face before them was removed, inside the box,
    // i.e. within the box's screen footprint. So the triangles outside the
    // box are drawn by cluster (their normal cones and screen rectangles):
    // clusters facing away are drawn only where their rectangle meets the
    // footprint, scissored to it; clusters meeting the footprint that face
    // neither way with both sides; the rest with back faces culled. Exact:
    // the same pixels as drawing both sides everywhere
    // (tests/render/passes/deform_pass_test). Outward faces wind
    // counter-clockwise on screen iff det(clip_from_world) < 0 (the
    // projective map's Jacobian has the sign of its matrix's determinant).
    const glm::dmat4 clip_from_world =
        glm::dmat4(view.clip_from_cam) * glm::dmat4(view.cam_from_world);
    last_culled_back_faces_ = cull_back_faces_ && InFrontOfNearPlane(clip_from_world, mesh_bounds_);
    if (mesh_outside_ && last_culled_back_faces_) {
      const glm::ivec4 footprint =
          ScreenRect(clip_from_world * placement_.object_from_box, glm::dvec3(0.0), glm::dvec3(1.0),
                     target.width(), target.height());
      const glm::dmat4 world_from_clip = glm::inverse(clip_from_world);
      const auto unproject = [&](double z) {
        const glm::dvec4 p = world_from_clip * glm::dvec4(0.0, 0.0, z, 1.0);
        return glm::dvec3(p) / p.w;
      };
      const glm::dvec3 eye(glm::inverse(glm::dmat4(view.cam_from_world))[3]);
      const glm::dvec3 along = unproject(1.0) - unproject(-1.0);  // orthographic rays
      // The cluster lists (members: no allocation a frame once grown).
      std::vector<uint32_t>& culled = culled_ids_;
      std::vector<uint32_t>& both_sides = both_sides_ids_;
      std::vector<uint32_t>& away_in_footprint = away_in_footprint_ids_;
      culled.clear();
      both_sides.clear();
      away_in_footprint.clear();
      const std::vector<MeshCluster>& clusters = mesh_outside_->clusters();
      for (uint32_t i = 0; i < clusters.size(); ++i) {
        const MeshCluster& c = clusters[i];
        const glm::ivec4 r = ScreenRect(clip_from_world, glm::dvec3(c.lo), glm::dvec3(c.hi),
                                        target.width(), target.height());
        const bool meets_footprint = r.x < footprint.x + footprint.z && footprint.x < r.x + r.z &&
                                     r.y < footprint.y + footprint.w && footprint.y < r.y + r.w;
        const bool away = view.orthographic ? c.FacesAwayAlong(along) : c.FacesAwayFrom(eye);
        const bool towards = view.orthographic ? c.FacesTowardsAlong(along) : c.FacesTowards(eye);
        if (away) {
          if (meets_footprint) away_in_footprint.push_back(i);
        } else if (meets_footprint && !towards) {
          both_sides.push_back(i);
        } else {
          culled.push_back(i);
        }
      }
      last_culled_clusters_ =
          clusters.size() - culled.size() - both_sides.size() - away_in_footprint.size();
      u.piece.Set(-1);  // no clipping
      mesh_outside_->DrawClusters(both_sides);
      glFrontFace(glm::determinant(clip_from_world) < 0 ? GL_CCW : GL_CW);
      glEnable(GL_CULL_FACE);
      glCullFace(GL_BACK);
      mesh_outside_->DrawClusters(culled);
      glCullFace(GL_FRONT);
      glEnable(GL_SCISSOR_TEST);
      glScissor(footprint.x, footprint.y, footprint.z, footprint.w);
      mesh_outside_->DrawClusters(away_in_footprint);
      glDisable(GL_SCISSOR_TEST);
      glDisable(GL_CULL_FACE);
      glCullFace(GL_BACK);
      glFrontFace(GL_CCW);
    } else if (mesh_outside_) {
      u.piece.Set(-1);  // no clipping
      mesh_outside_->Draw();
    }
    if (mesh_crossing_) {
      for (int i = 0; i < 6; ++i) glEnable(GL_CLIP_DISTANCE0 + i);
      for (int piece = 0; piece < 6; ++piece) {
        u.piece.Set(piece);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        mesh_crossing_->Draw();
      }
      for (int i = 0; i < 6; ++i) glDisable(GL_CLIP_DISTANCE0 + i);
    }
  }

  if (!options_.draw_rays) {
    glBindTextureUnit(0, 0);  // stage 1's implicit (seam blending)
    return;
  }
  // Stage 2: the box's back faces, one ray per fragment (the camera may be
  // inside the box; the rays start at max(entry, 0)).
  ProgramDesc desc{.vertex = "passes/deform_box.vert.glsl", .fragment = "passes/deform.frag.glsl"};
  desc.defines = options_.Defines();
  desc.defines.insert(desc.defines.end(), view_defines.begin(), view_defines.end());
  const bool flap = deformation_flap_.id() != 0;
  if (flap) desc.defines.push_back("DEFORM_FLAP");
  const Program& program = programs_.Get(desc);
  UseProgram(target, program, view);
  SetRayCoreUniforms(program, options_.RayCore());
  const auto& u = program.Typed<DeformBoxUniforms>();
  u.world_from_cam.Set(glm::inverse(view.cam_from_world));
  u.clip_z.Set(glm::vec2(core::ClipRangeZ(view.clip_from_cam)));
  u.object_from_box.Set(object_from_box);
  u.box_from_object.Set(box_from_object);
  set_implicit(u);
  u.deform_resolution.Set(static_cast<float>(deformation_resolution_));
  u.step.Set(options_.step_voxels * sdf_spacing_);
  u.thickness.Set(options_.thickness);
  u.alpha_lipschitz.Set(alpha_lipschitz_);
  u.warp_skip_cap.Set(warp_skip_cap_);
  u.warp_lipschitz.Set(3);
  glBindTextureUnit(3, warp_lipschitz_.id());
  u.sdf_margin.Set(sdf_margin_);
  u.base_color.Set(options_.base_color);
  u.cut_color.Set(options_.cut_color);
  u.sdf.Set(0);
  u.deformation.Set(1);
  glBindTextureUnit(0, sdf_.id());
  glBindTextureUnit(1, deformation_.id());
  if (flap) {
    u.deformation_flap.Set(2);
    glBindTextureUnit(2, deformation_flap_.id());
    u.alpha_components.Set(4);
    glBindTextureUnit(4, alpha_components_.id());
    u.alpha_components_flap.Set(5);
    glBindTextureUnit(5, alpha_components_flap_.id());
  }
  // The box's triangles face inwards: the far faces are front-facing (for a
  // mirroring placement, back-facing). Each pixel gets one fragment; its ray
  // is intersected with the box analytically, so either face set would do.
  glEnable(GL_CULL_FACE);
  glCullFace(glm::determinant(placement_.Linear()) > 0 ? GL_BACK : GL_FRONT);
  glBindVertexArray(box_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 36);
  glBindVertexArray(0);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glBindTextureUnit(0, 0);
  glBindTextureUnit(1, 0);
  glBindTextureUnit(2, 0);
  glBindTextureUnit(3, 0);
  glBindTextureUnit(4, 0);
  glBindTextureUnit(5, 0);
}

}  // namespace render
