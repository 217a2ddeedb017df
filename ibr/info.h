// `ibr info` as library calls: what this machine's GL gives, a readable
// summary of a dataset (cameras, views, depth, bounds, up), or of a volume
// file (type, size, spacing, data range and percentiles). Each returns the
// text to print, newline-terminated.
#pragma once

#include <filesystem>
#include <string>

namespace ibr {

// Makes a headless context and describes it (version, renderer, vendor,
// GLSL, platform) and the embedded shader files.
std::string GlInfoText();

// A dataset folder's summary (capture::ReadDataset: InputError on a bad one).
std::string DatasetInfoText(const std::filesystem::path& dir);

// A volume file's summary (core::ReadVolume: InputError on a bad one).
std::string VolumeInfoText(const std::filesystem::path& path);

// A volume file (.dat, .nrrd, .nhdr, .nii, .nii.gz) or a folder without a
// dataset.json (a DICOM series) described as a volume, anything else as a
// dataset; a folder that is neither names both possibilities in its error.
std::string PathInfoText(const std::filesystem::path& path);

}  // namespace ibr
