#!/usr/bin/env bash
# Installs every Debian package storey needs to build, test and run (DESIGN.md §2).
# Idempotent: when everything is present it returns in well under a second.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  clang clang-format libclang-rt-14-dev   # libFuzzer targets, sanitizer runtimes, formatting
  libeigen3-dev                           # all linear algebra (core/)
  libfcl-dev libccd-dev                   # robot-body collision checks against the map
  liboctomap-dev                          # FCL's octree and the mapping benchmark baseline
  libyaml-cpp-dev                         # configuration files (config/)
  libpcap-dev                             # recorded packets (pcap/pcapng)
  cyclonedds-dev cyclonedds-tools         # Go2's own DDS interface (idlc code generator)
  libembree-dev                           # simulated LiDAR ray casting (Embree 3)
  libassimp-dev                           # building meshes: OBJ, STL, PLY, DAE
  libpng-dev                              # report pictures (PNG writer)
  libgtest-dev libgmock-dev               # unit and integration tests
  libbenchmark-dev                        # storey-bench (Google Benchmark)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "bootstrap: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "bootstrap: installing ${#missing[@]} package(s): ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    SUDO="sudo -n"
  else
    echo "bootstrap: error: not root and no password-less sudo; install as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
if ! $SUDO apt-get update -qq; then
  echo "bootstrap: error: apt-get update failed (no network or no reachable Debian mirror)" >&2
  exit 1
fi
if ! $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"; then
  echo "bootstrap: error: apt-get install failed for: ${missing[*]}" >&2
  exit 1
fi
echo "bootstrap: done"
