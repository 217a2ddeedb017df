// DICOM series (a folder of slices) through GDCM (Debian libgdcm-dev): the
// slices are ordered by their position along the slice normal
// (gdcm::IPPSorter), decoded by gdcm::ImageReader (which handles the
// compressed transfer syntaxes GDCM was built with) and rescaled to real
// units with RescaleSlope / RescaleIntercept (HU for CT).
#include <fmt/format.h>
#include <gdcmIPPSorter.h>
#include <gdcmImageReader.h>
#include <gdcmScanner.h>
#include <gdcmTag.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/volume_io.h"

namespace core {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kWhere = "ReadDicomSeries";

ScalarType DicomType(const gdcm::PixelFormat& pf, const std::string& file) {
  if (pf.GetSamplesPerPixel() != 1) {
    ThrowFileError(kWhere, file, "{} samples per pixel: only grey-level slices are read",
                   pf.GetSamplesPerPixel());
  }
  switch (pf.GetScalarType()) {
    case gdcm::PixelFormat::UINT8:
      return ScalarType::kUint8;
    case gdcm::PixelFormat::INT8:
      return ScalarType::kInt8;
    case gdcm::PixelFormat::UINT12:
    case gdcm::PixelFormat::UINT16:
      return ScalarType::kUint16;
    case gdcm::PixelFormat::INT12:
    case gdcm::PixelFormat::INT16:
      return ScalarType::kInt16;
    case gdcm::PixelFormat::UINT32:
      return ScalarType::kUint32;
    case gdcm::PixelFormat::INT32:
      return ScalarType::kInt32;
    case gdcm::PixelFormat::FLOAT32:
      return ScalarType::kFloat32;
    case gdcm::PixelFormat::FLOAT64:
      return ScalarType::kFloat64;
    default:
      ThrowFileError(kWhere, file, "pixel format {} is not supported",
                     static_cast<int>(pf.GetScalarType()));
  }
}

}  // namespace

Volume ReadDicomSeries(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) ThrowFileError(kWhere, dir, "not a folder");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file(ec)) continue;
    if (files.size() >= static_cast<size_t>(kMaxVolumeExtent))
      ThrowFileError(kWhere, dir, "more than {} files", kMaxVolumeExtent);
    files.push_back(entry.path().string());
  }
  if (ec) ThrowFileError(kWhere, dir, "cannot list: {}", ec.message());
  std::sort(files.begin(), files.end());
  // The slices: files with an Image Position (Patient); other files (a
  // DICOMDIR, a README) are left out. One series only.
  const gdcm::Tag kPosition(0x0020, 0x0032), kSeries(0x0020, 0x000e);
  gdcm::Scanner scanner;
  scanner.AddTag(kPosition);
  scanner.AddTag(kSeries);
  if (!scanner.Scan(files)) ThrowFileError(kWhere, dir, "cannot scan the files");
  std::vector<std::string> slices;
  std::set<std::string> series;
  for (const std::string& f : files) {
    if (!scanner.IsKey(f.c_str()) || scanner.GetValue(f.c_str(), kPosition) == nullptr) continue;
    slices.push_back(f);
    const char* uid = scanner.GetValue(f.c_str(), kSeries);
    series.insert(uid ? uid : "");
  }
  if (slices.empty())
    ThrowFileError(kWhere, dir, "no DICOM slice (no file with an Image Position) in the folder");
  if (series.size() > 1) {
    ThrowFileError(kWhere, dir, "{} series in one folder: put each series in its own folder",
                   series.size());
  }
  double z_spacing = 0;
  if (slices.size() > 1) {
    gdcm::IPPSorter sorter;
    sorter.SetComputeZSpacing(true);
    sorter.SetZSpacingTolerance(1e-3);
    if (!sorter.Sort(slices)) {
      ThrowFileError(kWhere, dir,
                     "cannot order the {} slices by position (differing orientations, or two at "
                     "one position?)",
                     slices.size());
    }
    slices = sorter.GetFilenames();
    z_spacing = sorter.GetZSpacing();
  }
  Volume v;
  std::vector<double> slopes, intercepts;
  size_t slice_bytes = 0;
  for (size_t k = 0; k < slices.size(); ++k) {
    gdcm::ImageReader reader;
    reader.SetFileName(slices[k].c_str());
    if (!reader.Read()) ThrowFileError(kWhere, slices[k], "not a readable DICOM image");
    const gdcm::Image& image = reader.GetImage();
    const unsigned w = image.GetDimension(0), h = image.GetDimension(1);
    const unsigned depth = image.GetNumberOfDimensions() > 2 ? image.GetDimension(2) : 1;
    if (depth != 1) ThrowFileError(kWhere, slices[k], "a multi-frame image ({} frames)", depth);
    const ScalarType type = DicomType(image.GetPixelFormat(), slices[k]);
    if (k == 0) {
      v.type = type;
      v.dims = {static_cast<int>(w), static_cast<int>(h), static_cast<int>(slices.size())};
      const double sx = image.GetSpacing(0), sy = image.GetSpacing(1);
      v.spacing = {sx > 0 ? sx : 1.0, sy > 0 ? sy : 1.0, z_spacing > 0 ? z_spacing : 1.0};
      const size_t bytes =
          CheckedVolumeBytes(fmt::format("{}: '{}'", kWhere, dir.string()), v.dims, v.type);
      slice_bytes = bytes / slices.size();
      v.bytes.resize(bytes);
    } else if (static_cast<int>(w) != v.dims.x || static_cast<int>(h) != v.dims.y ||
               type != v.type) {
      ThrowFileError(kWhere, slices[k], "slice is {} x {} {}, the first is {} x {} {}", w, h,
                     ScalarTypeName(type), v.dims.x, v.dims.y, ScalarTypeName(v.type));
    }
    if (image.GetBufferLength() != slice_bytes) {
      ThrowFileError(kWhere, slices[k], "pixel data of {} bytes, {} x {} {} needs {}",
                     image.GetBufferLength(), w, h, ScalarTypeName(type), slice_bytes);
    }
    if (!image.GetBuffer(reinterpret_cast<char*>(v.bytes.data() + k * slice_bytes)))
      ThrowFileError(kWhere, slices[k], "cannot decode the pixel data");
    slopes.push_back(image.GetSlope());
    intercepts.push_back(image.GetIntercept());
  }
  const bool uniform =
      std::all_of(slopes.begin(), slopes.end(), [&](double s) { return s == slopes[0]; }) &&
      std::all_of(intercepts.begin(), intercepts.end(),
                  [&](double i) { return i == intercepts[0]; });
  if (uniform) {
    ApplyLinearScale(v, slopes[0], intercepts[0]);
  } else {
    // Per-slice factors (some PET series): real values in float32.
    Volume real = Volume::Zeros(v.dims, ScalarType::kFloat32, v.spacing);
    for (int z = 0; z < v.dims.z; ++z)
      for (int y = 0; y < v.dims.y; ++y)
        for (int x = 0; x < v.dims.x; ++x)
          real.SetValue(x, y, z, v.Value(x, y, z) * slopes[z] + intercepts[z]);
    v = std::move(real);
  }
  v.FitNormalization();
  return v;
}

}  // namespace core
