#!/usr/bin/env bash
# Installs zcheck's build dependencies from the Debian 12 archive (idempotent); with --test, also
# the real programs the tests start: COLMAP (its model converter writes real models), Blender
# (headless, its own Z pass), Slurm and munge (a local cluster), h5py (HDF5 maps written by
# another library), Chromium (headless: the dataset report's page as a browser shows it), and
# the independent implementations the tests hold zcheck to: OpenCV (lens models), Open3D (its
# closest-point queries) and VTK (its ray casts). Every module a test imports is installed here
# (tests/python/test_setup.py requires it).
set -euo pipefail
packages=(cmake ninja-build g++ pkg-config python3
          libembree-dev libglm-dev libopenimageio-dev openimageio-tools catch2 libtbb-dev
          libcli11-dev nlohmann-json3-dev libpng-dev libhdf5-dev
          pybind11-dev python3-dev python3-numpy python3-pytest python3-venv
          libegl-dev libgl1-mesa-dri)  # the llvmpipe yardstick of `zcheck bench --reference`
if [[ ${1:-} == --test ]]; then
    packages+=(colmap blender slurm-wlm munge python3-h5py chromium python3-opencv python3-open3d python3-vtk9)
fi
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
    sudo=""
    [[ $(id -u) -eq 0 ]] || sudo=sudo
    echo "installing: ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
