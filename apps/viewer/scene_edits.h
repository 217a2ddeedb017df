// The scene file a viewer session's edits produced (`ibr view --save-scene`):
// the file as read, each enabled deform and volume object's settings
// rewritten from the options the viewer ended with, the cameras the one
// view the window showed. Each rewritten object is read back through the
// same parser a load uses (ibr::DeformObjectOptionsFrom,
// ibr::VolumeObjectOptionsFrom) and must give the viewer's options: an edit
// without a scene key (so the saved file would draw something else) is an
// InputError naming the object, never a silently different file.
#pragma once

#include <string>

#include "ibr/scene_renderer.h"
#include "ibr/views.h"
#include "scene/scene.h"

namespace viewer {

// `base` with every deform key set from `options` (scene/scene_keys.cc's
// deform table; values written so they parse back to the same bits).
scene::Settings DeformSettings(const ibr::DeformObjectOptions& options, scene::Settings base,
                               const std::string& where);
// `base` with the volume keys set from `options` (the "deformations" list,
// map_size, mode, spacing, displacement_bits, lighting, jacobian; an edited
// transfer function as an inline "transfer" object).
scene::Settings VolumeSettings(const ibr::VolumeObjectOptions& options, scene::Settings base,
                               const std::string& where);

// `file` (what `loaded` was loaded from) with the loaded objects' options
// and one camera named `camera_name`.
scene::Scene SceneWithEdits(const scene::Scene& file, const ibr::LoadedScene& loaded,
                            const ibr::ViewCamera& camera, const std::string& camera_name = "view");

}  // namespace viewer
