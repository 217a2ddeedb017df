#!/usr/bin/python3
"""The VTK volume-rendering peer of `ibr bench volume` (shared/PEERS.md).

Renders a QVis volume with vtkGPUVolumeRayCastMapper offscreen (Debian's VTK
needs a display connection: run under `xvfb-run -a`), with the same transfer
function (control points in normalised scalar units, opacity per voxel), image
size and sampling distance as the ibr run, linear interpolation, shading on,
over an orbit of views, and prints one JSON line:
  {"first_frame_s": ..., "median_ms": ..., "min_ms": ..., "frames": N}
Usage: vtk_volume_peer.py DAT SIZE SAMPLE_DISTANCE_VOXELS TF_JSON [VIEWS]
TF_JSON: {"points": [[s, r, g, b, a], ...]} (as core::ReadTransferFunction).
"""
import json
import math
import os
import sys
import time

import numpy as np
import vtk


def read_qvis(dat):
    header = {}
    with open(dat) as f:
        for line in f:
            if ":" in line:
                k, v = line.split(":", 1)
                header[k.strip()] = v.strip()
    dims = [int(x) for x in header["Resolution"].split()]
    spacing = [float(x) for x in header.get("SliceThickness", "1 1 1").split()]
    dtype = {"UCHAR": np.uint8, "USHORT": np.uint16, "FLOAT": np.float32}[header["Format"]]
    raw = os.path.join(os.path.dirname(dat), header["ObjectFileName"])
    data = np.fromfile(raw, dtype=dtype)
    if data.size != dims[0] * dims[1] * dims[2]:
        raise SystemExit(f"vtk_volume_peer: {raw}: {data.size} voxels, header says {dims}")
    return data, dims, spacing, {np.uint8: 255.0, np.uint16: 65535.0, np.float32: 1.0}[dtype]


def main():
    dat, size, sample, tf_path = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    views = int(sys.argv[5]) if len(sys.argv) > 5 else 12
    data, dims, spacing, scale = read_qvis(dat)
    points = json.load(open(tf_path))["points"]

    t0 = time.perf_counter()
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.SetSpacing(*spacing)
    image.SetOrigin(*[-0.5 * (d - 1) * s for d, s in zip(dims, spacing)])
    from vtk.util import numpy_support
    arr = numpy_support.numpy_to_vtk(data, deep=True)
    image.GetPointData().SetScalars(arr)

    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    for s, r, g, b, a in points:
        color.AddRGBPoint(s * scale, r, g, b)
        opacity.AddPoint(s * scale, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOn()
    # Opacity per unit distance of one voxel (VTK's default unit is 1 world unit).
    prop.SetScalarOpacityUnitDistance(min(spacing))

    mapper = vtk.vtkGPUVolumeRayCastMapper()
    mapper.SetInputData(image)
    mapper.SetAutoAdjustSampleDistances(False)
    mapper.SetSampleDistance(sample * min(spacing))
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    renderer = vtk.vtkRenderer()
    renderer.AddVolume(volume)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(size, size)
    window.AddRenderer(renderer)
    renderer.ResetCamera()
    camera = renderer.GetActiveCamera()
    window.Render()
    first = time.perf_counter() - t0

    times = []
    for i in range(views):
        camera.Azimuth(360.0 / views)
        t = time.perf_counter()
        window.Render()
        times.append((time.perf_counter() - t) * 1e3)
    times.sort()
    print(json.dumps({"first_frame_s": first, "median_ms": times[len(times) // 2], "min_ms": times[0],
                      "frames": len(times)}))


if __name__ == "__main__":
    main()
