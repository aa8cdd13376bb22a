#!/usr/bin/env bash
# Installs the Debian 12 packages Lobesketch needs (only those missing, quietly) and builds
# the given CMake preset (default: release). Safe to run again and again.
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${1:-release}"

PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config git
  nlohmann-json3-dev libcli11-dev libglm-dev libeigen3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcgal-dev libopenmesh-dev libgmp-dev libmpfr-dev
  libnanoflann-dev libtinygltf-dev libstb-dev
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null; then SUDO="sudo"; else
      echo "setup: need root to install: ${missing[*]}" >&2; exit 1
    fi
  fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake --preset "$PRESET" >/dev/null
cmake --build --preset "$PRESET"
