#!/usr/bin/env python3
"""The README's tour, run as a newcomer would paste it (ctest: docs/README_tour).

Every ```sh block of README.md runs, in order, with `bash -euo pipefail` in
one fresh temporary folder, `ibr` on PATH (the build under test). The files a
"Your own data" block names stand in for a user's own: this script lays them
in the folder first (a mesh with UVs, a height map, a CT volume, an RGB-D
sequence, a COLMAP workspace), from the shared test data or made by ibr itself.
A block fails the test when it exits non-zero; its output is shown.

usage: readme_tour.py README.md BUILD_BIN_DIR SHARED_DATA_DIR [--keep]
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time


def sh_blocks(text):
    """The ```sh fenced blocks, in order (other languages are not run)."""
    return [m.group(1) for m in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M)]


def lay_stand_ins(folder, shared, source, ibr):
    """A user's own files, as the README's own-data blocks name them."""
    meshes = os.path.join(shared, "meshes")
    shutil.copy(os.path.join(meshes, "spot.obj"), os.path.join(folder, "mesh.obj"))
    shutil.copy(os.path.join(meshes, "spot_texture.png"), os.path.join(folder, "texture.png"))
    # A height map: 8-bit noise, as a user's bump map would be.
    subprocess.run(["oiiotool", "--pattern", "noise:type=uniform:min=0:max=1", "256x256", "1",
                    "--blur", "5x5", "-d", "uint8", "-o", os.path.join(folder, "height.png")],
                   check=True)
    # A real signed 16-bit CT (shared/data/tests-real/volumes/README.md says whose).
    shutil.copy(os.path.join(shared, "tests-real", "volumes", "ct_totalseg_example_ct_sm.nii.gz"),
                os.path.join(folder, "scan.nii.gz"))
    shutil.copytree(os.path.join(shared, "rgbd", "redwood5"), os.path.join(folder, "redwood"))
    # A COLMAP dense workspace, as `colmap image_undistorter` + stereo would leave it.
    ring = os.path.join(tempfile.mkdtemp(dir=folder), "ring")
    subprocess.run([ibr, "capture", "--mesh", os.path.join(folder, "mesh.obj"), "--rig", "ring:8",
                    "--size", "128", "--out", ring], check=True, capture_output=True)
    subprocess.run([ibr, "export", "colmap", ring, "--out", os.path.join(folder, "colmap")],
                   check=True, capture_output=True)
    shutil.rmtree(os.path.dirname(ring))


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    keep = "--keep" in sys.argv
    readme, bin_dir, shared = (os.path.abspath(a) for a in args)
    ibr = os.path.join(bin_dir, "ibr")
    with open(readme) as f:
        blocks = sh_blocks(f.read())
    if not blocks:
        print("README_tour: no ```sh block in", readme)
        return 1
    folder = tempfile.mkdtemp(prefix="readme-tour-")
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ["PATH"])
    failed = 0
    try:
        lay_stand_ins(folder, shared, os.path.dirname(readme), ibr)
        for i, block in enumerate(blocks, 1):
            start = time.time()
            run = subprocess.run(["bash", "-euo", "pipefail", "-c", block], cwd=folder, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            first = block.strip().splitlines()[0]
            status = "ok" if run.returncode == 0 else f"FAILED (exit {run.returncode})"
            print(f"block {i}/{len(blocks)} {status} in {time.time() - start:.1f} s: {first}")
            if run.returncode != 0:
                failed += 1
                print(block)
                print(run.stdout[-4000:])
    finally:
        if keep:
            print("kept", folder)
        else:
            shutil.rmtree(folder, ignore_errors=True)
    print(f"{len(blocks) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
