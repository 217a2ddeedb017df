#!/usr/bin/python3
"""The distance-field peer of `ibr bench deform` (bench/deform_bench.h):
OpenVDB's narrow-band level set of a closed triangle mesh
(pyopenvdb.FloatGrid.createLevelSetFromPolygons, Debian python3-openvdb),
built for each resolution with the voxel size ours uses (the box's longest
side / (resolution - 1)) and the same half width in voxels, timed around
the call alone (not the OBJ parse).

usage: openvdb_peer.py MESH.obj LONGEST HALF_WIDTH_VOXELS RES...
prints one line per resolution: "res R seconds S active N".
"""
import sys
import time

import numpy as np
import pyopenvdb as vdb


def read_obj(path):
    points, triangles = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                points.append([float(v) for v in parts[1:4]])
            elif parts[0] == "f":
                idx = [int(p.split("/")[0]) - 1 for p in parts[1:]]
                for k in range(1, len(idx) - 1):
                    triangles.append([idx[0], idx[k], idx[k + 1]])
    return np.array(points, dtype=np.float32), np.array(triangles, dtype=np.int32)


def main():
    if len(sys.argv) < 5:
        print(__doc__.strip().splitlines()[-2])
        sys.exit(2)
    points, triangles = read_obj(sys.argv[1])
    longest = float(sys.argv[2])
    half_width = float(sys.argv[3])
    for res in [int(r) for r in sys.argv[4:]]:
        voxel = longest / (res - 1)
        transform = vdb.createLinearTransform(voxelSize=voxel)
        start = time.perf_counter()
        grid = vdb.FloatGrid.createLevelSetFromPolygons(
            points, triangles=triangles, transform=transform, halfWidth=half_width)
        seconds = time.perf_counter() - start
        print(f"res {res} seconds {seconds:.6f} active {grid.activeVoxelCount()}", flush=True)


if __name__ == "__main__":
    main()
