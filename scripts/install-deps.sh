#!/usr/bin/env bash
# Installs the Debian 12 packages this project needs. Idempotent: only missing
# packages are installed; does nothing when everything is present.
# Runs apt-get directly as root, through sudo otherwise.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config ccache
  # headless GL: EGL (surfaceless/device), llvmpipe, GL loader, window for the viewer
  libegl-dev libegl1-mesa-dev libgl1-mesa-dri libgles-dev libepoxy-dev libglfw3-dev
  xvfb xauth
  # maths, images (openimageio-tools: its CMake config references iconvert),
  # camera maths, meshes
  libglm-dev libopenimageio-dev openimageio-tools python3-imath libopencv-dev libassimp-dev
  # triangle order for the post-transform vertex cache (render/gl/gpu_mesh.cc)
  libmeshoptimizer-dev
  # infrastructure
  libspdlog-dev libfmt-dev libcli11-dev nlohmann-json3-dev
  # viewer GUI
  libimgui-dev
  # tests and benchmarks
  googletest libgtest-dev libgmock-dev clang-format
  # plots for benchmarks; the real COLMAP binary for the interop tests
  gnuplot-nox colmap
  # libFuzzer targets for the parsers (IBR_FUZZ=ON, fuzz/): clang++ and its
  # runtime libraries (libclang_rt.fuzzer, asan, ubsan)
  clang libclang-rt-14-dev
  # the Open3D peer (bench/open3d_peer.py, run with /usr/bin/python3): TSDF integration and
  # voxel carving; OpenImageIO's binding reads the datasets' EXR depth maps there
  python3-open3d python3-openimageio
  # signed distance fields of meshes (core/distance_field_cgal.cc, header-only CGAL);
  # the OpenVDB level-set peer timed beside it by ibr bench deform
  libcgal-dev python3-openvdb
  # gzip-encoded NRRD volumes (core/volume_io.cc)
  zlib1g-dev
  # bzip2-encoded NRRD volumes and the NIfTI-1/2 header layouts (core/volume_io.cc);
  # DICOM series through GDCM (core/volume_dicom.cc)
  libbz2-dev libnifti2-dev libgdcm-dev
  # makes the slice-per-file NRRDs of a real CT at test time (tests/support/make_ct_slices.py)
  python3-nibabel
  # the VTK volume-rendering peer (bench/vtk_volume_peer.py: vtkGPUVolumeRayCastMapper under xvfb-run)
  python3-vtk9
  # meshes of depth objects and hulls: OpenVDB's volumeToMesh (ibr/mesh_export.cc, ibr export mesh)
  libopenvdb-dev
  # scripts/ibr-dask: batches of ibr jobs on Dask distributed (local cluster or a scheduler)
  python3-distributed
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
