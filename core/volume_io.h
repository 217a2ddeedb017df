// Volume files: the QVis pair (a text .dat header + a headerless .raw, the
// format of the Open SciVis / VolVis collections), NRRD (teem's format: raw,
// gzip or bzip2; attached data or detached in one file, a list or a %d
// pattern of files), NIfTI-1/2 (.nii, .nii.gz) and DICOM series (a folder of
// slices, through GDCM). Every reader returns the values in the file's own
// units (NIfTI scl_* and DICOM Rescale* applied) with FitNormalization done.
//
// Every reader checks the header (extents, type, spacing) and the size of the
// data against it BEFORE allocating the volume; data is read in bounded chunks
// so that a header claiming a large volume over a short stream never allocates
// more than the bytes actually present (plus one chunk). Bad input is one
// core::InputError naming the file and the problem. Stream overloads take a
// `name` used only in messages; the path overloads only open files.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <string_view>

#include "core/volume.h"

namespace core {

// ---- QVis (.dat + .raw) ----
// .dat lines "Key: value": ObjectFileName (the raw file, relative to the .dat),
// Resolution X Y Z, SliceThickness sx sy sz (spacing; default 1 1 1),
// Format UCHAR | USHORT (little endian) | FLOAT; other keys (TaggedFileName,
// ObjectModel, GridType, ...) are ignored. The raw file holds exactly
// X * Y * Z voxels, x fastest.
struct QVisHeader {
  std::string object_file;
  glm::ivec3 dims{0};
  glm::dvec3 spacing{1.0};
  ScalarType type = ScalarType::kUint8;
};
QVisHeader ReadQVisHeader(std::istream& dat, std::string_view name);
// Reads the voxels of `header` from `raw`, which must hold exactly the bytes
// the header says (no more, no fewer).
Volume ReadQVisRaw(std::istream& raw, const QVisHeader& header, std::string_view name);
Volume ReadQVis(const std::filesystem::path& dat_path);

void WriteQVisHeader(std::ostream& dat, const Volume& volume, std::string_view object_file);
void WriteQVisRaw(std::ostream& raw, const Volume& volume);
// Writes dat_path and the .raw beside it (same stem), atomically each.
void WriteQVis(const std::filesystem::path& dat_path, const Volume& volume);

// ---- NRRD ----
// Reads NRRD0001..NRRD0005 with dimension 3, every type but 64-bit integers
// and block (all the spec's aliases), encoding raw | gzip | bzip2, endian
// little | big, spacing from "spacings" or the lengths of "space directions"
// (1 where absent; the directions' orientation is not kept), "line skip" and
// "byte skip" (-1: the data end the file). Data is attached (after the blank
// line) or, for the path overload only, detached: "data file: NAME", "data
// file: LIST [SUBDIM]" (the remaining header lines name the files) or "data
// file: FORMAT MIN MAX STEP [SUBDIM]" (FORMAT with one %d); each file holds
// an equal part (SUBDIM axes; default 3 for one file, 2 for several), line
// and byte skip apply to each.
Volume ReadNrrd(std::istream& in, std::string_view name);
Volume ReadNrrd(const std::filesystem::path& path);

enum class NrrdEncoding { kRaw, kGzip };
void WriteNrrd(std::ostream& out, const Volume& volume, NrrdEncoding encoding);
void WriteNrrd(const std::filesystem::path& path, const Volume& volume, NrrdEncoding encoding);

// ---- NIfTI-1 / NIfTI-2 ----
// Single-file .nii, plain or gzip-compressed (.nii.gz, detected by the gzip
// magic), either byte order; datatypes (u)int8/16/32, float32, float64; 3D
// (higher dimensions only with extent 1). Spacing = |pixdim[1..3]| (the
// q/s-form orientation is not kept); scl_slope / scl_inter applied.
Volume ReadNifti(std::istream& in, std::string_view name);
Volume ReadNifti(const std::filesystem::path& path);

// ---- DICOM ----
// The slices in `dir` (files without an Image Position are left out; one
// series only), ordered along the slice normal; spacing from PixelSpacing
// and the slices' positions; RescaleSlope / RescaleIntercept applied.
Volume ReadDicomSeries(const std::filesystem::path& dir);

// By name: .dat (QVis), .nrrd / .nhdr (NRRD), .nii / .nii.gz (NIfTI), a
// folder (DICOM series).
Volume ReadVolume(const std::filesystem::path& path);

}  // namespace core
