#!/usr/bin/env bash
# Installs missing Debian packages (as root or with passwordless sudo; otherwise prints the apt-get
# line and stops): the toolchain, PoCL, the libraries, and for the viewer GLFW, GLM and OpenGL, with
# Xvfb, Mesa and xdotool for its headless tests; Slurm with munge for the farm tests (a one-node
# cluster, tests/farm/slurm_cluster.sh) and python3-venv for Open Job Description's runner. Then
# configures and builds Release into build/ (binary build/narval) and generates the default cloud.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo
  libopenvdb-dev libboost-iostreams-dev libtbb-dev libopenexr-dev libpng-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev libgmock-dev
  clang libclang-rt-dev
  libglfw3-dev libglm-dev libgl1-mesa-dri libglx-mesa0 xvfb xauth xdotool
  slurmctld slurmd slurm-client munge python3-venv)

# The package names are Debian's (12, bookworm) and Ubuntu's; elsewhere say so and build with
# whatever is installed (CMake names anything missing).
if ! command -v dpkg-query >/dev/null || ! grep -qiE '^(ID|ID_LIKE)=.*(debian|ubuntu)' /etc/os-release 2>/dev/null; then
  echo "setup: not Debian or Ubuntu; install the equivalents of these Debian packages yourself:" >&2
  echo "  ${packages[*]}" >&2
  packages=()
fi

source scripts/apt_packages.sh
apt_install_missing setup "${packages[@]}"

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"

# The default scene's cloud is generated, not committed (deterministic for its seed).
if [ ! -f scenes/data/cloud_128.vdb ]; then
  mkdir -p scenes/data
  build/narval make-cloud scenes/data/cloud_128.vdb --resolution 128 --seed 1
fi
