// Height maps for displacement mapping, generated deterministically in code,
// and the "ground truth model": a base mesh tessellated finely and displaced
// along its interpolated normals (Kautz-Seidel 2001, sec. 3; Chen-Chang's
// "ground truth model"). Heights are in [0, 1]; 0 = no elevation.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>

#include "core/enum_names.h"
#include "core/image.h"
#include "core/mesh.h"

namespace core {

enum class HeightPattern {
  kConstant,  // every texel = `level`
  kBumps,     // smooth cosine bumps on a grid
  kNoise,     // fractal value noise (4 octaves), seeded
  kBricks,    // raised bricks with mortar grooves (sharp edges)
  kSteps,     // terraces: 4 sharp steps along u
  kSpikes,    // thin isolated spikes (1-3 texels wide) on a flat base
};

inline constexpr EnumName<HeightPattern> kHeightPatternNames[] = {
    {HeightPattern::kConstant, "constant"}, {HeightPattern::kBumps, "bumps"},
    {HeightPattern::kNoise, "noise"},       {HeightPattern::kBricks, "bricks"},
    {HeightPattern::kSteps, "steps"},       {HeightPattern::kSpikes, "spikes"},
};
static_assert(EnumNamesUnique(kHeightPatternNames));
// "constant", "bumps", ... ; throws InputError for an unknown name.
HeightPattern HeightPatternFromName(const std::string& name);
std::string HeightPatternName(HeightPattern pattern);

struct HeightMapOptions {
  HeightPattern pattern = HeightPattern::kBumps;
  int size = 256;      // texels per side (square, power of two not required)
  uint32_t seed = 1;   // noise and spike positions
  float level = 0.5f;  // kConstant's value; other patterns' maximum height
  void Check() const;
};

// A 1-channel float image, values in [0, level], tileable (wraps at the edges).
ImageF MakeHeightMap(const HeightMapOptions& options);

// Bilinear sample with wrap-around at uv (texel centres at (i + 0.5)/size),
// the same rule as GL's LINEAR + REPEAT, for CPU references.
float SampleHeightBilinear(const ImageF& height, glm::vec2 uv);
// Nearest-texel sample with wrap-around (GL's NEAREST + REPEAT).
float SampleHeightNearest(const ImageF& height, glm::vec2 uv);

struct DisplacedMeshOptions {
  float max_displacement = 0.1f;  // scene units for height 1.0
  float tiling = 1.0f;            // the height map repeats `tiling` times across uv [0,1]
  int subdivisions = 16;          // each base triangle becomes subdivisions^2 triangles
  bool bilinear = true;           // sample heights bilinearly (else nearest texel)
  void Check() const;
};

// Every base triangle is subdivided; each new vertex sits at the interpolated
// position + height(uv * tiling) * max_displacement * normalize(interpolated
// normal). Normals of the result are recomputed from the displaced geometry
// (area-weighted). The base mesh needs normals and uvs.
TriangleMesh TessellateDisplaced(const TriangleMesh& base, const ImageF& height,
                                 const DisplacedMeshOptions& options);

}  // namespace core
