#!/usr/bin/python3
"""The VTK volume-rendering peer of `ibr bench volume` (shared/PEERS.md).

Renders a QVis volume with vtkGPUVolumeRayCastMapper offscreen (Debian's VTK
needs a display connection: run under `xvfb-run -a`), with the same transfer
function (control points in normalised scalar units, opacity per voxel), image
size and sampling distance as the ibr run, linear interpolation, shading on,
over an orbit of views, and prints one JSON line:
  {"first_frame_s": ..., "median_ms": ..., "min_ms": ..., "frames": N}
Usage: vtk_volume_peer.py DAT SIZE SAMPLE_DISTANCE_VOXELS TF_JSON [VIEWS [WARP_JSON]]
TF_JSON: {"points": [[s, r, g, b, a], ...]} (as core::ReadTransferFunction).

With WARP_JSON ("vtk prewarped"), the volume is first warped on the CPU by
the same inverse displacement map the ibr pass reads (Correa 2006 eq. 2, 10:
a point p' shows the volume at p' + A D(M^-1 p'), its cut mask alpha < 0.5
empty), resampled once onto the ibr pass's proxy box at the volume's voxel
spacing: vtkGridTransform (the map's texels as a displacement grid, linear)
through vtkImageReslice (linear), the mask resampled alike and applied. That
resample is what an edit of the map costs this way; the JSON line adds
"resample_ms" and "warped_voxels" (output voxel count) and, when the WARP_JSON
names "out_raw", writes the warped volume there (float32, normalised scalar,
x fastest) for the bench's check against its own displacement.
WARP_JSON: {"map_raw": float32 (D.x, D.y, D.z, alpha) per texel, x fastest,
D in map units; "map_dims": [x, y, z]; "placement_lo", "placement_scale": the
map cube in volume texture space (axis-aligned, eq. 10's M); "proxy_lo",
"proxy_hi": the output box in volume texture space; optional "out_raw"}.
Differs from the ibr pass within one map texel outside the map's cube (the
grid is padded by one identity texel; ibr switches to the identity at the
cube's faces) and where 0 < alpha < 1 (a scalar volume has no per-sample
opacity factor: kept at full where alpha >= 0.5).
"""
import json
import math
import os
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support


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


def image_data(values, dims, spacing, origin):
    image = vtk.vtkImageData()
    image.SetDimensions(*dims)
    image.SetSpacing(*spacing)
    image.SetOrigin(*origin)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(values, deep=True))
    return image


def prewarp(image, dims, spacing, scale, dtype, warp):
    """The volume warped by the map (module docstring); (image, seconds, voxel count)."""
    mdims = [int(v) for v in warp["map_dims"]]
    texels = np.fromfile(warp["map_raw"], dtype=np.float32)
    if texels.size != 4 * mdims[0] * mdims[1] * mdims[2]:
        raise SystemExit(f"vtk_volume_peer: {warp['map_raw']}: {texels.size} floats, map {mdims}")
    texels = texels.reshape(mdims[2], mdims[1], mdims[0], 4)
    extent = np.array(dims, dtype=np.float64) * np.array(spacing)  # world size of the box
    lo, size = np.array(warp["placement_lo"]), np.array(warp["placement_scale"])
    # Volume texture coordinate t -> VTK world: voxel i sits at t = (i + 0.5) / n
    # in ibr and at (i - (n - 1) / 2) spacing here, so world = (t - 0.5) extent.
    world = lambda t: (np.asarray(t) - 0.5) * extent
    t0 = time.perf_counter()
    # D in world units (A D, A = diag(scale)), padded by a copy of the edge
    # texels: linear filtering of the padded grid is GL_LINEAR with
    # CLAMP_TO_EDGE inside the cube, as the ibr pass reads its map.
    disp = np.pad(texels[..., :3] * (size * extent), ((1, 1), (1, 1), (1, 1), (0, 0)), mode="edge")
    alpha = np.pad(texels[..., 3], 1, mode="edge")
    grid_dims = [d + 2 for d in mdims]
    grid_spacing = size * extent / np.array(mdims)
    grid_origin = world(lo + size * (-0.5) / np.array(mdims))
    disp_grid = image_data(disp.reshape(-1, 3), grid_dims, grid_spacing, grid_origin)
    alpha_grid = image_data(alpha.reshape(-1), grid_dims, grid_spacing, grid_origin)
    transform = vtk.vtkGridTransform()
    transform.SetDisplacementGridData(disp_grid)
    transform.SetInterpolationModeToLinear()
    plo, phi = np.array(warp["proxy_lo"]), np.array(warp["proxy_hi"])
    out_dims = [max(1, int(round((h - l) * n))) for l, h, n in zip(plo, phi, dims)]
    out_origin = world(plo + 0.5 / np.array(dims))  # voxel centres of the proxy box

    def resliced(source, transform_or_none, background):
        r = vtk.vtkImageReslice()
        r.SetInputData(source)
        if transform_or_none is not None:
            r.SetResliceTransform(transform_or_none)
        r.SetInterpolationModeToLinear()
        r.SetOutputSpacing(*spacing)
        r.SetOutputOrigin(*out_origin)
        r.SetOutputExtent(0, out_dims[0] - 1, 0, out_dims[1] - 1, 0, out_dims[2] - 1)
        r.SetOutputScalarType(vtk.VTK_FLOAT)
        r.SetBackgroundLevel(background)
        r.Update()
        return numpy_support.vtk_to_numpy(r.GetOutput().GetPointData().GetScalars())

    # Outside the map's cube the map is the identity (eq. 10): the volume
    # resampled as it is there.
    centres = [out_origin[a] + spacing[a] * np.arange(out_dims[a]) for a in range(3)]
    t = [c / extent[a] + 0.5 for a, c in enumerate(centres)]  # volume texture coordinates
    inside = [(t[a] >= lo[a]) & (t[a] <= lo[a] + size[a]) for a in range(3)]
    inside = (inside[2][:, None, None] & inside[1][None, :, None] & inside[0][None, None, :]).reshape(-1)
    warped = np.where(inside, resliced(image, transform, 0.0), resliced(image, None, 0.0))
    mask = np.where(inside, resliced(alpha_grid, None, 1.0), 1.0)
    warped = np.where(mask >= 0.5, warped, 0.0).astype(np.float32)
    # Rendered in the volume's own scalar type, as the unwarped volume is.
    info = np.iinfo(dtype) if np.issubdtype(dtype, np.integer) else None
    stored = np.clip(np.rint(warped), info.min, info.max) if info else warped
    result = image_data(stored.astype(dtype), out_dims, spacing, out_origin)
    seconds = time.perf_counter() - t0
    if "out_raw" in warp:
        (warped / scale).astype(np.float32).tofile(warp["out_raw"])
    return result, seconds, out_dims


def main():
    dat, size, sample, tf_path = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    views = int(sys.argv[5]) if len(sys.argv) > 5 else 12
    warp = json.load(open(sys.argv[6])) if len(sys.argv) > 6 else None
    data, dims, spacing, scale = read_qvis(dat)
    points = json.load(open(tf_path))["points"]

    t0 = time.perf_counter()
    image = image_data(data, dims, spacing, [-0.5 * (d - 1) * s for d, s in zip(dims, spacing)])
    extra = {}
    if warp is not None:
        image, seconds, out_dims = prewarp(image, dims, spacing, scale, data.dtype, warp)
        extra = {"resample_ms": seconds * 1e3, "warped_voxels": out_dims}
        t0 = time.perf_counter()  # the first frame below: the upload of the warped volume

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
                      "frames": len(times), **extra}))


if __name__ == "__main__":
    main()
