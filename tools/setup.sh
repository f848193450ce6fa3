#!/usr/bin/env bash
# Installs splat's build dependencies from Debian's packages (idempotent: packages that
# are already installed are skipped, and apt is not touched at all when none is missing).
set -euo pipefail
packages=(build-essential cmake pkg-config libglm-dev libopenimageio-dev openimageio-tools
          libtbb-dev catch2 libcli11-dev nlohmann-json3-dev libnifti2-dev zlib1g-dev libgdcm-dev
          clang-14 libclang-rt-14-dev mricron-data chromium
          xvfb xauth  # xvfb, xauth: tools/bench/vs_vtk.py runs VTK without a display
          python3 python3-nibabel python3-pydicom teem-apps libbz2-dev  # tests: faults, third-party files and oracles
          libopenmpi-dev openmpi-bin  # splat::mpi (docs/parallel.md)
          libblosc-dev libopenvdb-dev  # OME-Zarr blosc chunks; OpenVDB files (optional: SPLAT_OPENVDB)
          python3-openvdb python3-zarr python3-numcodecs  # tests: VDB and Zarr files written by their own libraries
          pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib)  # the Python module (docs/python.md)
# SPLAT_WITH_ICET=1 also installs ParaView's IceT for splat::mpi's optional IceT compositor
# (docs/building.md; Debian ships IceT only inside ParaView: paraview-dev, ~100 MB to
# download, ~700 MB on disk). CI asks for it (.ci/run); a newcomer's setup does not.
if [ "${SPLAT_WITH_ICET:-0}" = 1 ]; then packages+=(paraview-dev); fi
# SPLAT_WITH_VTK=1 also installs VTK's Python bindings for the optional side-by-side benchmark
# (tools/bench/vs_vtk.py, docs/performance.md); without them it is skipped.
if [ "${SPLAT_WITH_VTK:-0}" = 1 ]; then packages+=(python3-vtk9); fi
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "setup: all dependencies present"
    exit 0
fi
echo "setup: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
start=$(date +%s)
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: installed in $(($(date +%s) - start)) s"
