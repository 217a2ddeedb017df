// The double-precision CPU reference of render::VolumePass's DVR (Correa,
// Silver, Chen 2006, sec. 4.2) at exactly the pass's sample positions: the
// slices the pass draws for a view (render::MakeSlices with
// VolumePass::DvrSlicing), each pixel centre's point on every slice displaced
// through the maps as the GPU stores them (core::Displace over the stored,
// dequantised maps, read only inside their core::ActiveBox), the volume
// sampled trilinearly (core::SampleTrilinear), classified by the transfer
// function's 256-entry table with its opacities corrected for the slice
// spacing (core::OpacityCorrectedTable, as the pass uploads it), with linear
// interpolation, and composited back to front, premultiplied. Used by
// tests/render/passes/volume_pass_test (the agreement bounds) and the
// report's gallery (bench/gallery.h). No lighting: compare with a pass built
// with render::VolumeLighting::kNone.
//
// Cameras: any render::ViewSetup, perspective or orthographic; pixel centres
// are mapped to camera space through the inverse of its clip_from_cam (the
// float matrix the GPU uses, inverted in double).
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "core/image.h"
#include "core/transfer_function.h"
#include "core/volume.h"
#include "core/volume_displacement.h"
#include "render/passes/pass.h"
#include "render/passes/volume_pass.h"

namespace ibr {

// What the GPU sees of each map: stored at `displacement_bits` (8, 16 or 32,
// VolumePassOptions::displacement_bits), dequantised.
std::vector<core::DisplacementMap> VolumeStoredMaps(const std::vector<render::VolumeMapInput>& maps,
                                                    int displacement_bits);
// The stored maps placed as the pass places them, each read only inside the
// core::ActiveBox of its stored map (where the pass reads it). `stored` is
// VolumeStoredMaps(maps, displacement_bits) and must outlive the result.
std::vector<core::PlacedMap> VolumePlacedMaps(const std::vector<render::VolumeMapInput>& maps,
                                              int displacement_bits,
                                              const std::vector<core::DisplacementMap>& stored);

// The normalised density at volume texture point p, 0 outside [0, 1]^3.
double VolumeDensity(const core::Volume& volume, const glm::dvec3& p);

// The camera-space line through the centre of pixel (col, row) of a
// width x height image seen by `view`: its points at the near and far clip
// planes (NDC z = -1 and 1).
struct CamLine {
  glm::dvec3 near{0.0}, far{0.0};
  glm::dvec3 AtZ(double z) const;  // the line's point at camera z
};
CamLine PixelLineInCam(const render::ViewSetup& view, int width, int height, int col, int row);

struct DvrReferenceImage {
  core::Image<double> color;  // RGBA premultiplied, image rows
  // 1 where a sample lies within 1e-4 (proxy box units) of a proxy face:
  // whether the GPU rasterises it is a tie, so such pixels are not compared.
  core::Image8 ambiguous;
};

// The reference for `pass` (built from volume, transfer and maps, DVR mode)
// seen by `view` into a width x height image.
DvrReferenceImage DvrReference(const core::Volume& volume, const core::TransferFunction& transfer,
                               const std::vector<render::VolumeMapInput>& maps,
                               const render::VolumePass& pass, const render::ViewSetup& view,
                               int width, int height);

}  // namespace ibr
