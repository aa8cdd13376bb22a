#!/usr/bin/env bash
# Installs the Debian 12 packages Lobesketch needs (only those missing, quietly), the Khronos
# glTF validator the export tests run (npm, pinned, into build/tools/gltf-validator), the npm
# L-system library scripts/lsystem-compare.sh runs (build/tools/lindenmayer) and builds the
# given CMake preset (default: release). Safe to run again and again. With `--blender` after
# the preset it also installs Blender (headless imports of the exported trees,
# scripts/blender-import.sh; scripts/test.sh asks for it, a developer need not).
#
# The preset `demo` (scripts/demo.sh) installs only what building and running `lobesketch`
# needs and builds only that program, into build/release: no test frameworks, sanitizer
# runtimes, Xvfb, Node.js or validator, and none of the tests and benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."

PRESET="${1:-release}"
WITH_BLENDER="${2:-}"
if [ -n "$WITH_BLENDER" ] && [ "$WITH_BLENDER" != "--blender" ]; then
  echo "setup: unknown option $WITH_BLENDER (usage: scripts/setup.sh [PRESET] [--blender])" >&2; exit 2
fi

# What building and running `lobesketch` needs (the demo).
PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config git
  nlohmann-json3-dev libcli11-dev libglm-dev libeigen3-dev
  libcgal-dev libopenmesh-dev libgmp-dev libmpfr-dev
  libnanoflann-dev libtinygltf-dev libstb-dev libmeshoptimizer-dev
  libvulkan-dev mesa-vulkan-drivers glslc libopenxr-dev libopenxr-loader1
  libglfw3-dev libimgui-dev
)
# What the tests, benchmarks, the sanitizer build and the window tests need besides.
if [ "$PRESET" != "demo" ]; then
  PACKAGES+=(libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev xvfb xauth)
fi
# Blender 3.4 and the numpy its glTF importer needs (docs/export.md: 127 packages, 541 MB).
[ -n "$WITH_BLENDER" ] && PACKAGES+=(blender python3-numpy)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
# Node.js runs the glTF validator (tests only); a node/npm already on PATH (from any source) is kept.
if [ "$PRESET" != "demo" ]; then
  command -v node >/dev/null || missing+=(nodejs)
  command -v npm >/dev/null || missing+=(npm)
fi

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

if [ "$PRESET" = "demo" ]; then
  cmake --preset demo >/dev/null
  cmake --build --preset demo
  exit 0
fi

# The Khronos glTF validator, pinned; tests/support/gltf_validate.mjs and the export tests use it.
GLTF_VALIDATOR_VERSION="2.0.0-dev.3.10"
GLTF_VALIDATOR_DIR="build/tools/gltf-validator"
installed="$(node -p "require('./$GLTF_VALIDATOR_DIR/node_modules/gltf-validator/package.json').version" 2>/dev/null || true)"
if [ "$installed" != "$GLTF_VALIDATOR_VERSION" ]; then
  echo "setup: installing gltf-validator@$GLTF_VALIDATOR_VERSION into $GLTF_VALIDATOR_DIR"
  mkdir -p "$GLTF_VALIDATOR_DIR"
  npm install --prefix "$GLTF_VALIDATOR_DIR" --no-audit --no-fund --save-exact --loglevel=error \
    "gltf-validator@$GLTF_VALIDATOR_VERSION" >/dev/null
fi

# The npm L-system library `lindenmayer`, pinned: scripts/lsystem-compare.sh runs it beside the
# L-system benchmarks (docs/lsystems.md, Performance). A dev-time tool only.
LINDENMAYER_VERSION="1.5.4"
LINDENMAYER_DIR="build/tools/lindenmayer"
installed="$(node -p "require('./$LINDENMAYER_DIR/node_modules/lindenmayer/package.json').version" 2>/dev/null || true)"
if [ "$installed" != "$LINDENMAYER_VERSION" ]; then
  echo "setup: installing lindenmayer@$LINDENMAYER_VERSION into $LINDENMAYER_DIR"
  mkdir -p "$LINDENMAYER_DIR"
  # Only the comparison script needs it: a failed install is said and does not stop the setup.
  npm install --prefix "$LINDENMAYER_DIR" --no-audit --no-fund --save-exact --loglevel=error \
    "lindenmayer@$LINDENMAYER_VERSION" >/dev/null ||
    echo "setup: could not install lindenmayer (only scripts/lsystem-compare.sh needs it)" >&2
fi

cmake --preset "$PRESET" >/dev/null
cmake --build --preset "$PRESET"
