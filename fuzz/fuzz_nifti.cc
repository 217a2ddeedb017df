// libFuzzer target: NIfTI-1/2 volumes (.nii, or .nii.gz detected by the gzip
// magic) through core::ReadNifti; no writer, so only a clean rejection or a
// volume (see fuzz_reader.h).
#include "core/volume_io.h"
#include "fuzz/fuzz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fuzz::FuzzReaderOnly(data, size,
                              [](std::istream& in) { return core::ReadNifti(in, "fuzz.nii"); });
}
