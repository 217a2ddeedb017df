// The logic behind `ibr volume`: a volume file, deformations (Correa, Silver,
// Chen 2006; core::kDeformationTable) placed in it, rendered by render::VolumePass from
// an orbit view or a dataset's cameras into PNGs. Also the scene builder the
// volume benchmark shares.
#pragma once

#include <filesystem>
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/transfer_function.h"
#include "core/volume.h"
#include "core/volume_displacement.h"
#include "ibr/views.h"
#include "ibr/volume_object.h"
#include "render/passes/volume_pass.h"

namespace ibr {

struct VolumeRenderRequest {
  std::filesystem::path volume;  // core::ReadVolume: QVis, NRRD, NIfTI, DICOM folder
  // Deformations (each its own placed map), map size, pass options and iso
  // value (stored units): what a scene's volume object takes
  // (VolumeObjectOptionsFrom).
  VolumeObjectOptions object;
  std::string
      transfer;  // preset or JSON file; empty: the preset named like the volume, else "ramp"
  // Instead of `transfer`: window width and level (centre) in stored units
  // (WindowLevelTransfer).
  std::optional<glm::dvec2> window_level;
  int size = 512;  // pixels (orbit views)
  // The orbit view (OrbitCameraView around the volume's bounding
  // sphere): +z up, as the light (the paper's Fig. 4); 30 degrees round, 20 up.
  OrbitCamera orbit{.elevation_deg = 20, .azimuth_deg = 30};
  std::filesystem::path cameras;  // a dataset directory: one image per camera (else one orbit view)
  std::filesystem::path out;      // FILE.png (one view) or DIR (one PNG per camera)
};

struct VolumeRenderResult {
  int images = 0;
  double median_ms = 0;  // per frame, first view, after warm-up
  int slices = 0;        // DVR slices of the first view
  glm::dvec3 proxy_lo{0.0}, proxy_hi{1.0};
};

// What `ibr volume` prints: the volume, its deformations and mode, the
// images written, the frame time, slices and proxy box, on one line.
std::string VolumeReportText(const VolumeRenderRequest& request, const VolumeRenderResult& result);

// A perspective view orbiting the origin at `distance`, z up, focal 1.2 size
// (OrbitCameraView): the bench's and gallery's fixed framing.
render::ViewSetup VolumeOrbitView(double azimuth_deg, double elevation_deg, double distance,
                                  int size, double radius);

// Needs a current GL context. Writes atomically (nothing partial on failure).
VolumeRenderResult RenderVolume(const VolumeRenderRequest& request);

// One frame of `pass` seen by `view` into a size x size RGBA32F target (no
// 8-bit rounding at each slice): premultiplied colour, image rows.
core::ImageF DrawVolumeFloat(render::VolumePass& pass, const render::ViewSetup& view, int size);

}  // namespace ibr
