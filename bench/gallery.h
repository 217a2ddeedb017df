// The hard views of `ibr report`: each technique where it is hardest
// (displaced surfaces at a grazing view, where silhouettes come from the
// displacement; depth objects and visual hulls of a concave object from an
// oblique view; a solid cut through a mesh, against the double sphere
// tracer; a peeled volume (Correa, Silver, Chen 2006) seen obliquely into
// the cut, against the double DVR reference of verify/volume_reference.h at the
// pass's own slices) beside its truth rendered in the same run, with a heat
// map of the depth error (the colour error for the translucent volume, which
// has no single depth).
#pragma once

#include <string>
#include <vector>

#include "core/image.h"
#include "render/gl/shader_program.h"

namespace bench {

// The heat map's colours: |depth - truth| / scale, clamped to [0, 1], on a
// black -> red -> yellow -> white ramp (piecewise linear in thirds; dark
// means right) where both cover the pixel; magenta where only the render
// covers it (extra surface), cyan where only the truth does (missing
// surface), dark grey where neither. Coverage masks: nonzero = covered.
core::Image8 DepthErrorHeatMap(const core::Image8& covered, const core::ImageF& depth,
                               const core::Image8& truth_covered, const core::ImageF& truth_depth,
                               double scale);
// The same ramp on max_c |color_c - truth_c| / scale over the four channels
// of premultiplied RGBA in [0, 1] (translucent renders: no single depth);
// dark grey where both are exactly 0 (empty in both).
core::Image8 ColorErrorHeatMap(const core::ImageF& color, const core::ImageF& truth_color,
                               double scale);
// The colour error of a float RGBA render against a truth of the same size,
// one value per pixel that either covers (alpha > 0): the largest
// premultiplied channel difference, in units of 1/255.
std::vector<double> ColorErrors(const core::ImageF& color, const core::ImageF& truth);
// The ramp alone: t in [0, 1] (clamped) -> RGB.
void HeatRamp(double t, uint8_t rgb[3]);

struct GalleryEntry {
  // The report's family id: "displacement", "depth_object", "deform", "volume".
  std::string family;
  std::string title;    // "ncs, grazing view (8 deg)"
  std::string caption;  // the errors against the truth, the heat map's scale
  core::Image8 render, truth, heat;
};

struct GalleryOptions {
  int size = 256;      // pixels per side of every view
  int map_size = 256;  // depth objects: cube-rig map size, pixels
  bool quick = false;  // the cup only for depth objects; smaller volume maps
  // Family ids to render (GalleryEntry::family); empty: every family.
  std::vector<std::string> families;
};

// Needs a current context (and ../shared/data for the bunny, Spot and the
// volume; absent = skipped).
std::vector<GalleryEntry> RenderGallery(render::ProgramCache& programs,
                                        const GalleryOptions& options);

}  // namespace bench
