// Colour images as sampled textures: the one upload of an RGBA8 image that
// capture's textured meshes, scene meshes and the noise backdrop share, and
// the sampling state a frame shown scaled needs.
#pragma once

#include "core/image.h"
#include "render/gl/handles.h"

namespace render {

enum class TextureWrap {
  kRepeat,       // texture coordinates wrap (tiled textures, a sphere's longitude)
  kClampToEdge,  // the edge texels extend (a sphere's poles, a frame's border)
};

// `rgba` (4 channels, row 0 uploaded first) as an immutable RGBA8 2D texture
// with LINEAR filtering and the given wrap modes (s along u, t along v).
Texture UploadRgba8Texture(const core::Image8& rgba, TextureWrap wrap_s, TextureWrap wrap_t);

// LINEAR filtering and CLAMP_TO_EDGE on an existing 2D texture: a frame
// stretched over a window, bilinear when reduced, unchanged at full size.
void SampleLinearClamped(const Texture& texture);

}  // namespace render
