# Writes OUT/ct_slices/ (one gzip-encoded NRRD data file per axial slice) and the
# two detached headers that read them (%d pattern, LIST) from the real CT
# SRC (ct_totalseg_example_ct_sm.nii.gz of ../shared/data/tests-real/volumes).
# Run by ctest as the fixture of the slice-per-file tests, with Debian's
# python3-nibabel:  /usr/bin/python3 make_ct_slices.py SRC OUT
import gzip
import os
import sys

import nibabel
import numpy

src, out = sys.argv[1], sys.argv[2]
image = nibabel.load(src)
data = numpy.asarray(image.dataobj)  # int16, x fastest in NIfTI = NRRD order
assert data.dtype == numpy.int16 and data.ndim == 3
nx, ny, nz = data.shape
sx, sy, sz = (float(z) for z in image.header.get_zooms())
os.makedirs(os.path.join(out, "ct_slices"), exist_ok=True)
names = []
for k in range(nz):
    name = "ct_slices/slice%03d.raw.gz" % k
    # mtime=0: the same bytes on every run.
    with open(os.path.join(out, name), "wb") as raw, gzip.GzipFile(fileobj=raw, mode="wb", mtime=0) as f:
        f.write(data[:, :, k].astype("<i2").tobytes(order="F"))
    names.append(name)
common = (
    "NRRD0004\n# slices of %s (make_ct_slices.py)\n"
    "type: short\ndimension: 3\nsizes: %d %d %d\nspacings: %g %g %g\n"
    "endian: little\nencoding: gzip\n" % (os.path.basename(src), nx, ny, nz, sx, sy, sz))
with open(os.path.join(out, "ct_slices_pattern.nhdr"), "w") as f:
    f.write(common + "data file: ct_slices/slice%%03d.raw.gz 0 %d 1 2\n" % (nz - 1))
with open(os.path.join(out, "ct_slices_list.nhdr"), "w") as f:
    f.write(common + "data file: LIST\n" + "".join(n + "\n" for n in names))
