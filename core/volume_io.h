// Volume files: the QVis pair (a text .dat header + a headerless .raw, the
// format of the Open SciVis / VolVis collections) and NRRD (teem's format, raw
// or gzip encoding, attached or detached data).
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
// Reads NRRD0001..NRRD0005 with dimension 3, type (u)int8/uint16/float (and
// their aliases), encoding raw | gzip, endian little | big, spacing from
// "spacings" or the lengths of "space directions" (1 where absent). Data is
// attached (after the blank line) or, for the path overload only, in a
// detached "data file" beside the header.
Volume ReadNrrd(std::istream& in, std::string_view name);
Volume ReadNrrd(const std::filesystem::path& path);

enum class NrrdEncoding { kRaw, kGzip };
void WriteNrrd(std::ostream& out, const Volume& volume, NrrdEncoding encoding);
void WriteNrrd(const std::filesystem::path& path, const Volume& volume, NrrdEncoding encoding);

// By extension: .dat (QVis) or .nrrd / .nhdr (NRRD).
Volume ReadVolume(const std::filesystem::path& path);

}  // namespace core
