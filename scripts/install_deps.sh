#!/usr/bin/env bash
# Installs every build and test dependency of subflow from Debian 12 packages.
# Idempotent: packages already present are left as they are.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libeigen3-dev
  libopencv-dev
  libceres-dev libsuitesparse-dev libgoogle-glog-dev libgflags-dev
  libopenblas0-pthread  # the BLAS of CHOLMOD (CMakeLists.txt: SYSTEM_BLAS_LIBRARY)
  libtet1.5-dev
  libtbb-dev
  libembree-dev  # ray casts against hulls (geometry/ray_caster.h)
  libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  libtinygltf-dev
  libpugixml-dev libtomlplusplus-dev  # calibration importers: Qualisys XML, Pose2Sim/Anipose TOML
  libgtest-dev libgmock-dev libbenchmark-dev
  libopenmesh-dev  # optional reference in bench/subdivision_bench
  clang libclang-rt-14-dev  # the fuzz harnesses (libFuzzer, ASan, UBSan): scripts/fuzz.sh
  # Tests of the exports and the viewer: Blender reads the point caches and the .glb
  # (python3-numpy: its glTF importer needs it), Chromium opens the viewer headless.
  blender python3-numpy
  chromium
  # A single-node Slurm cluster for tests/cluster/slurm_plan_test.sh (slurmctld, slurmd, munge).
  slurm-wlm munge
)
# node and npm (for the viewer's three.js bundle and the glTF validator): Debian's, unless
# the machine already has a node.
command -v node > /dev/null 2>&1 || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  echo "install_deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The viewer's npm packages (three.js, esbuild, gltf-validator), pinned by
# viewer/package-lock.json; the build bundles three.js into the subflow binary.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
stamp="$root/viewer/node_modules/.installed-package-lock.json"
if ! cmp -s "$root/viewer/package-lock.json" "$stamp"; then
  echo "install_deps: npm ci in viewer/"
  (cd "$root/viewer" && npm ci --no-audit --no-fund --loglevel=error)
  cp "$root/viewer/package-lock.json" "$stamp"
fi
