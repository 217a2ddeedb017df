#!/usr/bin/python3
"""The Open3D peer of the depth objects (issue 5, "Accuracy and its cost").

Reads one of our datasets (capture/dataset.h: dataset.json, depth EXR = float
camera z with 0 = invalid, mask PNG) and reconstructs the object with Open3D
0.16 (Debian's python3-open3d) the two ways a user would:

  tsdf:N              ScalableTSDFVolume, voxel = E / N (E = the largest edge
                      of the dataset's bounds), truncation 4 voxels,
                      integrate every depth map, extract_triangle_mesh().
  carve-depth:N       VoxelGrid.create_dense over the bounds' cube at N^3,
                      carve_depth_map() with every depth map.
  carve-silhouette:N  the same with carve_silhouette() and every mask.

Each result is written as OUT/<method>_<N>.ply (world coordinates, the
dataset's frame). Voxel grids become box meshes: exactly the faces of kept
voxels that touch a carved (or outside) voxel, two triangles each, so the
mesh is the carved set itself, blocky at the voxel size, with no smoothing
added on the peer's behalf. OUT/peer.json records per method the wall times
in seconds (integration or carving, extraction of the mesh, writing it),
counts (views used, voxels, vertices, triangles) and the settings.

Cameras: PINHOLE / SIMPLE_PINHOLE only. Open3D's integrate() and carve_*()
take a PinholeCameraIntrinsic; there is no orthographic camera, so the cube
rig's ORTHOGRAPHIC maps cannot be fed to it. They are skipped and counted
("skipped_orthographic"); a dataset with no pinhole view is an error. Use a
perspective capture of the same object (ibr capture --rig sphere:N) for the
peer. Our cameras put pixel centres at +0.5, Open3D's at integer
coordinates: cx, cy are shifted by -0.5.

Orthographic maps (the cube rig), with --orthographic far-pinhole: each
becomes a pinhole camera on its axis FAR_FACTOR (1000) bounds edges behind its
image plane, its depth shifted by that distance and its focal length chosen
so the scale is the orthographic one at the bounds' centre: the rays then
deviate from parallel by at most edge / 2000 radians, a lateral error of
1/4000 of an edge at the box faces (a sixteenth of a voxel at 256 voxels an
edge), so Open3D's TSDF integrates the very maps our export reads.

Usage: /usr/bin/python3 open3d_peer.py DATASET --out DIR
           [--methods tsdf:128,tsdf:256,carve-depth:128,...]
           [--orthographic skip|far-pinhole]
Exit status 1 with one line "open3d_peer: ..." on stderr for bad input.
"""

import argparse
import json
import os
import sys
import time

import numpy as np


class InputError(Exception):
    pass


def fail(message):
    raise InputError(message)


def read_exr(path):
    try:
        import OpenImageIO as oiio
    except ImportError:
        fail("reading EXR depth needs OpenImageIO's Python binding (apt-get install python3-openimageio)")
    inp = oiio.ImageInput.open(path)
    if inp is None:
        fail(f"cannot open '{path}': {oiio.geterror()}")
    try:
        pixels = inp.read_image(oiio.FLOAT)
    finally:
        inp.close()
    if pixels is None:
        fail(f"cannot read '{path}'")
    pixels = np.asarray(pixels, dtype=np.float32)
    if pixels.ndim == 3:
        pixels = pixels[:, :, 0]
    return np.ascontiguousarray(pixels)


def read_png(path, o3d):
    image = o3d.io.read_image(path)
    array = np.asarray(image)
    if array.size == 0:
        fail(f"cannot read '{path}'")
    return array


FAR_FACTOR = 1000.0


def load_dataset(root, o3d, orthographic="skip"):
    manifest_path = os.path.join(root, "dataset.json")
    try:
        with open(manifest_path) as f:
            manifest = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        fail(f"'{manifest_path}': {e}")
    if manifest.get("format") != "ibr-dataset":
        fail(f"'{manifest_path}': not an ibr-dataset manifest")
    bounds = manifest.get("bounds")
    if not bounds:
        fail(f"'{manifest_path}': no \"bounds\" (the voxel grid needs the object's box)")
    cameras = {c["id"]: c for c in manifest["cameras"]}
    views, skipped = [], 0
    for v in manifest["views"]:
        cam = cameras.get(v["camera"])
        if cam is None:
            fail(f"'{manifest_path}': view {v['name']} names unknown camera {v['camera']}")
        model, p = cam["model"], cam["params"]
        shift = 0.0  # far-pinhole: depth offset of the camera behind the image plane
        cam_from_world = np.eye(4)
        cam_from_world[:3, :] = np.asarray(v["cam_from_world"], dtype=np.float64)
        if model == "ORTHOGRAPHIC":
            if orthographic != "far-pinhole" or not bounds:
                skipped += 1
                continue
            sx, sy, cx, cy = p
            lo_b = np.asarray(bounds["min"], dtype=np.float64)
            hi_b = np.asarray(bounds["max"], dtype=np.float64)
            shift = FAR_FACTOR * float(np.max(hi_b - lo_b))
            z_ref = float((cam_from_world @ np.append(0.5 * (lo_b + hi_b), 1.0))[2])
            fx, fy = sx * (shift + z_ref), sy * (shift + z_ref)
            move = np.eye(4)
            move[2, 3] = shift
            cam_from_world = move @ cam_from_world
        elif model == "PINHOLE":
            fx, fy, cx, cy = p
        elif model == "SIMPLE_PINHOLE":
            fx, cx, cy = p
            fy = fx
        else:
            fail(f"'{manifest_path}': camera {cam['id']} is {model}; undistorted pinhole cameras only")
        w, h = int(cam["width"]), int(cam["height"])
        intrinsic = o3d.camera.PinholeCameraIntrinsic(w, h, fx, fy, cx - 0.5, cy - 0.5)
        extrinsic = cam_from_world
        params = o3d.camera.PinholeCameraParameters()
        params.intrinsic = intrinsic
        params.extrinsic = extrinsic
        view = {"name": v["name"], "params": params, "width": w, "height": h}
        if v.get("depth"):
            depth = read_exr(os.path.join(root, v["depth"]))
            if depth.shape != (h, w):
                fail(f"{v['depth']}: {depth.shape[1]}x{depth.shape[0]}, camera says {w}x{h}")
            depth[~np.isfinite(depth)] = 0
            depth[depth < 0] = 0
            if shift:
                depth[depth > 0] += shift
            view["depth"] = depth
        if v.get("color"):
            color = read_png(os.path.join(root, v["color"]), o3d)
            if color.ndim == 2:
                color = np.stack([color] * 3, axis=-1)
            view["color"] = np.ascontiguousarray(color[:, :, :3]).astype(np.uint8)
        if v.get("mask"):
            mask = read_png(os.path.join(root, v["mask"]), o3d)
            if mask.ndim == 3:
                mask = mask[:, :, 0]
            view["mask"] = mask
        views.append(view)
    if not views:
        fail(f"'{manifest_path}': no pinhole view ({skipped} orthographic views: Open3D has no orthographic "
             "camera; capture the object with a perspective rig, e.g. --rig sphere:6)")
    lo = np.asarray(bounds["min"], dtype=np.float64)
    hi = np.asarray(bounds["max"], dtype=np.float64)
    return views, lo, hi, skipped


def cube_of(lo, hi, pad_fraction):
    """The bounds' cube (edge = their largest extent, padded), centred on them."""
    edge = float(np.max(hi - lo)) * (1 + 2 * pad_fraction)
    centre = 0.5 * (lo + hi)
    return centre - 0.5 * edge, edge


def run_tsdf(views, lo, hi, n, o3d):
    _, edge = cube_of(lo, hi, 0.0)
    voxel = edge / n
    volume = o3d.pipelines.integration.ScalableTSDFVolume(
        voxel_length=voxel, sdf_trunc=4 * voxel,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.RGB8)
    used = 0
    t0 = time.perf_counter()
    for v in views:
        if "depth" not in v:
            continue
        color = v.get("color")
        if color is None:
            color = np.full((v["height"], v["width"], 3), 200, np.uint8)
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(color), o3d.geometry.Image(v["depth"]), depth_scale=1.0,
            depth_trunc=1e30, convert_rgb_to_intensity=False)
        volume.integrate(rgbd, v["params"].intrinsic, v["params"].extrinsic)
        used += 1
    t1 = time.perf_counter()
    if used == 0:
        fail("tsdf: no view has depth")
    mesh = volume.extract_triangle_mesh()
    t2 = time.perf_counter()
    return mesh, {"voxel_size": voxel, "sdf_trunc": 4 * voxel, "views_used": used,
                  "integrate_s": t1 - t0, "extract_s": t2 - t1}


# Unit cube faces (outward normal axis, sign) as quads, counter-clockwise seen from outside.
_FACE_QUADS = {
    (0, -1): [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)],
    (0, +1): [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)],
    (1, -1): [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)],
    (1, +1): [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)],
    (2, -1): [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)],
    (2, +1): [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
}


def box_mesh(occupancy, origin, voxel, o3d):
    """Exposed faces of the occupied voxels as a triangle mesh (world coordinates)."""
    padded = np.pad(occupancy, 1)
    vertices, triangles = [], []
    count = 0
    for (axis, sign), quad in _FACE_QUADS.items():
        neighbour = np.roll(padded, -sign, axis=axis)[1:-1, 1:-1, 1:-1]
        idx = np.argwhere(occupancy & ~neighbour)  # (k, 3) voxel indices
        if len(idx) == 0:
            continue
        corners = idx[:, None, :] + np.asarray(quad)[None, :, :]  # (k, 4, 3)
        vertices.append(corners.reshape(-1, 3))
        base = count + 4 * np.arange(len(idx))[:, None]
        triangles.append(np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], axis=0))
        count += 4 * len(idx)
    mesh = o3d.geometry.TriangleMesh()
    if count:
        mesh.vertices = o3d.utility.Vector3dVector(origin + voxel * np.concatenate(vertices).astype(np.float64))
        mesh.triangles = o3d.utility.Vector3iVector(np.concatenate(triangles).astype(np.int32))
    return mesh


def run_carve(views, lo, hi, n, kind, o3d):
    origin, edge = cube_of(lo, hi, 0.02)
    voxel = edge / n
    t0 = time.perf_counter()
    grid = o3d.geometry.VoxelGrid.create_dense(origin, np.zeros(3), voxel, edge, edge, edge)
    t1 = time.perf_counter()
    used = 0
    for v in views:
        if kind == "depth":
            if "depth" not in v:
                continue
            # Open3D keeps a voxel if one of its corners is at or behind the
            # depth; depth 0 (background, holes) carves the whole ray.
            grid.carve_depth_map(o3d.geometry.Image(v["depth"]), v["params"], keep_voxels_outside_image=False)
        else:
            if "mask" not in v:
                continue
            silhouette = (v["mask"] > 127).astype(np.float32)
            grid.carve_silhouette(o3d.geometry.Image(silhouette), v["params"], keep_voxels_outside_image=False)
        used += 1
    t2 = time.perf_counter()
    if used == 0:
        fail(f"carve-{kind}: no view has a {kind if kind == 'depth' else 'mask'}")
    # Occupancy by asking the grid about every voxel centre (create_dense may
    # round the count up to n + 1): one vectorised call; get_voxels() builds a
    # Python object per voxel and takes ~10x longer.
    m = n + 1
    ijk = np.stack(np.meshgrid(*[np.arange(m)] * 3, indexing="ij"), -1).reshape(-1, 3)
    centres = np.asarray(grid.origin) + (ijk + 0.5) * voxel
    occupancy = np.asarray(grid.check_if_included(o3d.utility.Vector3dVector(centres)), dtype=bool).reshape(m, m, m)
    mesh = box_mesh(occupancy, np.asarray(grid.origin), voxel, o3d)
    t3 = time.perf_counter()
    return mesh, {"voxel_size": voxel, "grid": n, "views_used": used, "voxels_kept": int(occupancy.sum()),
                  "create_s": t1 - t0, "integrate_s": t2 - t1, "extract_s": t3 - t2}


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dataset")
    parser.add_argument("--out", required=True)
    parser.add_argument("--methods", default="tsdf:128,tsdf:256,carve-depth:128,carve-silhouette:128")
    parser.add_argument("--orthographic", choices=("skip", "far-pinhole"), default="skip")
    args = parser.parse_args(argv)
    methods = []
    for item in args.methods.split(","):
        name, _, res = item.partition(":")
        if name not in ("tsdf", "carve-depth", "carve-silhouette") or not res.isdigit() or not 8 <= int(res) <= 1024:
            fail(f"--methods: '{item}' (tsdf:N, carve-depth:N, carve-silhouette:N with N in 8..1024)")
        methods.append((name, int(res)))

    # Open3D's OpenMP threads spin while they wait by default; on a shared,
    # loaded machine (2 cores here) that made TSDF integration 10-30x slower
    # than with passive waiting. Passive is the peer's best case: kept
    # unless the caller set a policy.
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    t_import = time.perf_counter()
    import open3d as o3d
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    import_s = time.perf_counter() - t_import
    t_read = time.perf_counter()
    views, lo, hi, skipped = load_dataset(args.dataset, o3d, args.orthographic)
    read_s = time.perf_counter() - t_read
    os.makedirs(args.out, exist_ok=True)
    report = {"open3d": o3d.__version__, "dataset": os.path.abspath(args.dataset), "views": len(views),
              "skipped_orthographic": skipped,
              "omp_wait_policy": os.environ.get("OMP_WAIT_POLICY"), "omp_num_threads": os.environ.get("OMP_NUM_THREADS", ""), "import_s": import_s, "read_s": read_s,
              "bounds": {"min": lo.tolist(), "max": hi.tolist()}, "results": []}
    for name, n in methods:
        if name == "tsdf":
            mesh, info = run_tsdf(views, lo, hi, n, o3d)
        else:
            mesh, info = run_carve(views, lo, hi, n, name.split("-")[1], o3d)
        path = os.path.join(args.out, f"{name}_{n}.ply")
        t0 = time.perf_counter()
        if len(mesh.triangles) and not o3d.io.write_triangle_mesh(path, mesh, write_ascii=False):
            fail(f"cannot write '{path}'")
        info.update({"method": name, "resolution": n, "mesh": path if len(mesh.triangles) else "",
                     "vertices": len(mesh.vertices), "triangles": len(mesh.triangles),
                     "write_s": time.perf_counter() - t0})
        report["results"].append(info)
        print(f"open3d_peer: {name}:{n}: {info['integrate_s']:.3f} s + extract {info['extract_s']:.3f} s, "
              f"{info['triangles']} triangles", file=sys.stderr)
    tmp = os.path.join(args.out, "peer.json.tmp")
    with open(tmp, "w") as f:
        json.dump(report, f, indent=1)
    os.replace(tmp, os.path.join(args.out, "peer.json"))


if __name__ == "__main__":
    try:
        main(sys.argv[1:])
    except InputError as e:
        print(f"open3d_peer: {e}", file=sys.stderr)
        sys.exit(1)
