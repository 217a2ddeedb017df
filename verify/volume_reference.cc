#include "verify/volume_reference.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "render/cores/slicing.h"

namespace ibr {

std::vector<core::DisplacementMap> VolumeStoredMaps(const std::vector<render::VolumeMapInput>& maps,
                                                    int displacement_bits) {
  std::vector<core::DisplacementMap> out;
  for (const auto& m : maps)
    out.push_back(
        core::DequantizeDisplacementMap(core::StoreDisplacementMap(m.map, displacement_bits)));
  return out;
}

std::vector<core::PlacedMap> VolumePlacedMaps(const std::vector<render::VolumeMapInput>& maps,
                                              int displacement_bits,
                                              const std::vector<core::DisplacementMap>& stored) {
  IBR_CHECK_EQ(maps.size(), stored.size());
  std::vector<core::PlacedMap> placed;
  for (size_t i = 0; i < stored.size(); ++i)
    placed.push_back({&stored[i], maps[i].placement,
                      core::ActiveBox(core::StoreDisplacementMap(maps[i].map, displacement_bits))});
  return placed;
}

double VolumeDensity(const core::Volume& volume, const glm::dvec3& p) {
  if (p.x < 0 || p.y < 0 || p.z < 0 || p.x > 1 || p.y > 1 || p.z > 1) return 0;
  return core::SampleTrilinear(volume, p);
}

glm::dvec3 CamLine::AtZ(double z) const {
  return near + (z - near.z) / (far.z - near.z) * (far - near);
}

CamLine PixelLineInCam(const render::ViewSetup& view, int width, int height, int col, int row) {
  IBR_CHECK(width > 0 && height > 0);
  // Image (u, v) -> NDC: x = 2u / width - 1, y = 1 - 2v / height (GL window
  // y = height - v, core/projection.h).
  const glm::dmat4 cam_from_clip = glm::inverse(glm::dmat4(view.clip_from_cam));
  const double x = 2 * (col + 0.5) / width - 1, y = 1 - 2 * (row + 0.5) / height;
  auto at = [&](double ndc_z) {
    const glm::dvec4 p = cam_from_clip * glm::dvec4(x, y, ndc_z, 1.0);
    return glm::dvec3(p) / p.w;
  };
  return {at(-1.0), at(1.0)};
}

DvrReferenceImage DvrReference(const core::Volume& volume, const core::TransferFunction& transfer,
                               const std::vector<render::VolumeMapInput>& maps,
                               const render::VolumePass& pass, const render::ViewSetup& view,
                               int width, int height) {
  IBR_CHECK(pass.options().mode == render::VolumeMode::kDvr);
  const glm::dmat4 world_from_box(pass.world_from_proxy());
  const glm::dmat4 cam_from_box = glm::dmat4(view.cam_from_world) * world_from_box;
  const glm::dmat4 box_from_cam = glm::inverse(cam_from_box);
  const render::SliceStack stack = render::MakeSlices(
      render::SliceBox{pass.world_from_proxy()},
      render::SliceView{view.cam_from_world, view.orthographic}, pass.DvrSlicing(view));
  const core::Box3 proxy = pass.proxy_box();
  const int bits = pass.options().displacement_bits;
  const auto stored = VolumeStoredMaps(maps, bits);
  const auto placed = VolumePlacedMaps(maps, bits, stored);
  // The pass's table: opacities corrected for its exponent (rounded to float
  // as the pass rounds it), interpolated linearly after the correction.
  const std::vector<glm::vec4> table = core::OpacityCorrectedTable(
      transfer.Table(256), static_cast<float>(stack.spacing_world / pass.voxel_world()));
  // Screen slices are planes of constant camera z, in drawing order (back to front).
  std::vector<double> slice_z;
  for (const render::Slice& slice : stack.slices)
    slice_z.push_back((cam_from_box * glm::dvec4(glm::dvec3(slice.p_in_box[0]), 1.0)).z);
  DvrReferenceImage r{core::Image<double>(width, height, 4, 0.0),
                      core::Image8(width, height, 1, 0)};
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const CamLine line = PixelLineInCam(view, width, height, col, row);
      for (const double z : slice_z) {
        const glm::dvec3 b = glm::dvec3(box_from_cam * glm::dvec4(line.AtZ(z), 1.0));
        const double margin = std::min({b.x, b.y, b.z, 1 - b.x, 1 - b.y, 1 - b.z});
        if (std::abs(margin) < 1e-4) r.ambiguous.at(col, row) = 1;
        if (margin < 0) continue;
        const glm::dvec3 pp = proxy.lo + b * (proxy.hi - proxy.lo);
        const core::DisplacedSample d = core::Displace(placed, pp);
        if (d.alpha < 0.5) continue;
        const double u = std::clamp(VolumeDensity(volume, d.p), 0.0, 1.0) * 255;
        const int i0 = static_cast<int>(std::floor(u)), i1 = std::min(i0 + 1, 255);
        const glm::dvec4 tf = glm::mix(glm::dvec4(table[i0]), glm::dvec4(table[i1]), u - i0);
        const double a = tf.a * d.alpha;
        if (!(a > 0)) continue;
        for (int c = 0; c < 3; ++c)
          r.color.at(col, row, c) = tf[c] * a + (1 - a) * r.color.at(col, row, c);
        r.color.at(col, row, 3) = a + (1 - a) * r.color.at(col, row, 3);
      }
    }
  return r;
}

}  // namespace ibr
