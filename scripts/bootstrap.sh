#!/usr/bin/env bash
# Installs rths's dependencies (Debian 12 packages only), makes sure LCM's udpm transport can
# work on this host, and builds into build/. Run as root on a fresh Debian 12.
#   bash scripts/bootstrap.sh           what running needs: the packages the programs build and run
#                                       with, and the rths-* programs (no tests, benches or fuzzers)
#   bash scripts/bootstrap.sh --tests   everything: also the packages the test suite uses (Octave,
#                                       Chromium, Slurm, clang, the JDK, ...), every test and bench,
#                                       and the fuzz tree (build-fuzz/); what .ci/run runs
# Idempotent: a second run only installs what is missing and rebuilds what changed.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

tests=0
case "${1:-}" in
  "") ;;
  --tests) tests=1 ;;
  *) echo "usage: bash scripts/bootstrap.sh [--tests]" >&2; exit 2 ;;
esac

# What the programs build and run with.
packages=(
  cmake ninja-build g++ pkg-config
  liblcm-dev liblcm-bin            # LCM 1.3.1: library, lcm-gen, lcm-logger/-logplayer/-spy
  libeigen3-dev libsundials-dev    # linear algebra, CVODE/ARKODE
  libfftw3-dev                     # FFTs for spectral estimation (identification, Figs. 6-8)
  libfmt-dev doctest-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libssl-dev                       # SHA-256 of scenario files (libcrypto)
  iproute2                         # ip route, for the multicast route below
  gnuplot-nox                      # figures (PNG via pngcairo)
  libcpp-httplib-dev libjs-dygraphs  # the live monitor's web server and its plotting library (rths watch)
  libmatio-dev                     # .mat export (rths export): MATLAB v5, and v7.3 through HDF5
  libhdf5-dev                      # a sweep's table.h5 (lib/sweep/table.h)
)
# What the test suite adds (--tests).
test_packages=(
  default-jdk-headless liblcm-java # the Java types jar (lcm-spy, MATLAB) and examples/java_plant
  clang-14 libclang-rt-14-dev      # libFuzzer + ASan/UBSan for the fuzz targets (fuzz/, build-fuzz/)
  python3-h5py                     # the test that reads a sweep's table.h5 in Python
  octave                           # the test that loads an exported .mat in GNU Octave
  chromium                         # the tests that screenshot a run report and the live monitor headless
  unzip                            # the test that lists the Java types jar
  bsdutils util-linux mount        # script (a terminal for cli_test), unshare and mount (reliability_test)
  python3 python3-numpy            # examples/python_plant (a plant participant in Python) and its test
  slurmctld slurmd slurm-client munge  # the test that runs a sweep on a one-node Slurm (tests/slurm/one_node.sh)
  busybox-static                   # the bundle's test: a chroot with busybox's shell only (tests/bundle/chroot.sh)
)
if ((tests)); then packages+=("${test_packages[@]}"); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "bootstrap: missing packages: ${missing[*]} (run as root, or: sudo apt-get install ${missing[*]})" >&2
    exit 1
  fi
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

# LCM's udpm needs a route for multicast; without one lcm_create fails or stalls 10 s.
# Loopback keeps every run on this host.
if ! ip route show 224.0.0.0/4 2>/dev/null | grep -q .; then
  if [[ $(id -u) -eq 0 ]] && ip route add 224.0.0.0/4 dev lo; then
    echo "bootstrap: added the multicast route: ip route add 224.0.0.0/4 dev lo"
  else
    echo "bootstrap: no multicast route; as root run: ip route add 224.0.0.0/4 dev lo" >&2
    echo "           (until then use: ./rths run --transport memq)" >&2
  fi
fi

# Release: -O2 without -g (CMakeLists.txt); unity: a library's sources compiled 8 to a file, each
# template instantiated once per batch. Both leave the code as it was and halve the compile time.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
if ((tests)); then
  cmake --build build -j"$(nproc)"
  # The libFuzzer targets (docs/fuzzing.md), with clang in a tree of their own; ctest runs them.
  cmake -S fuzz -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
    -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_C_COMPILER=clang-14
  cmake --build build-fuzz -j"$(nproc)"
else
  # The rths-* programs and what they need (CMakeLists.txt's `programs` target).
  cmake --build build --target programs -j"$(nproc)"
fi
