#!/usr/bin/env bash
# Installs what the ARFLEX build, tests and cell need on Debian bookworm, and only what is
# missing: a second run does nothing and takes well under a second. Run as root (or with
# sudo available). Maven artifacts are fetched by Maven itself on the first build.
set -euo pipefail

# One line per need; keep in step with ../shared/DEPENDENCIES.md and the module READMEs.
PACKAGES=(
  openjdk-17-jdk-headless maven          # Java build (Java 17: SPI Fly/Jetty break on 25)
  gcc g++ cmake ninja-build pkg-config   # native build
  ccache                                 # compiler cache: the suite's two native builds (D76)
  libexpat1-dev                          # the host API reads contracts (rt-core host_contract.h)
  libcmocka-dev libgtest-dev             # C and C++ unit tests
  libmujoco-dev libqhull-dev             # physics (MuJoCo's CMake config needs qhull)
  libosmesa6-dev                         # headless offscreen rendering
  libapriltag-dev libeigen3-dev          # fiducials (the apriltag-utils library is in it), linear algebra
  libopencv-core-dev libopencv-imgproc-dev libopencv-calib3d-dev
  rt-tests stress-ng                     # cyclictest reference and load for benchmarks
  python3                                # benchmark reports, console password hash
  chromium chromium-driver               # browser tests of the web console
)

# POSIX message queues are listed in /dev/mqueue only when that filesystem is mounted (some
# containers do not mount it). Tests check there that nothing leaked, so mount it.
if [ ! -d /dev/mqueue ] || ! grep -q " /dev/mqueue mqueue " /proc/mounts; then
  if [ "$(id -u)" -eq 0 ]; then
    mkdir -p /dev/mqueue && mount -t mqueue none /dev/mqueue \
      || echo "arflex setup: warning: could not mount /dev/mqueue; queue leak checks are weaker" >&2
  else
    echo "arflex setup: warning: /dev/mqueue is not mounted (needs root); queue leak checks are weaker" >&2
  fi
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "arflex setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
