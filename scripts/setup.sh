#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Installs what rfbsim needs on Debian 12 (only what is missing), installs the page's npm packages from
# the lock file, and builds: everything, or only the --target(s) named (the demos build just what they run).
# Used by run-demo.sh and test.sh; safe to run again, and quick when nothing changed.
#   scripts/setup.sh [--with-browser] [--build-dir DIR] [--target NAME]... [extra cmake -D options...]
set -euo pipefail
cd "$(dirname "$0")/.."

with_browser=0
build_dir=build
cmake_args=()
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --with-browser) with_browser=1 ;;
    --build-dir) build_dir="$2"; shift ;;
    --target) targets+=(--target "$2"); shift ;;
    -D*) cmake_args+=("$1") ;;
    *) echo "setup.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
  shift
done

# Debian packages: the build's libraries and tools.
packages=(build-essential cmake ninja-build pkg-config git
  libvncserver-dev libegl-dev libgl-dev libopengl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri libgbm-dev
  libode-dev libyaml-cpp-dev libpng-dev libeigen3-dev libwebsocketpp-dev libboost-system-dev libasio-dev catch2 libssl-dev libsqlite3-dev libzstd-dev zlib1g-dev
  nlohmann-json3-dev libcli11-dev libfreetype-dev fonts-dejavu-core libavcodec-dev libavformat-dev libswscale-dev libavutil-dev
  ffmpeg)
command -v node >/dev/null 2>&1 || packages+=(nodejs)
command -v npm >/dev/null 2>&1 || packages+=(npm)
# Test-only: Chromium for the browser tests, clang and its runtimes (libFuzzer, sanitizers) for scripts/fuzz.sh,
# HAProxy for the cluster tests (scripts/run-cluster-demo.sh; a study installs it on its balancer host),
# MuJoCo for examples/mujoco_rfb, and TigerVNC's Xvnc with a few X11 programs (glxgears, xeyes, Xlib for our
# key-echo program) for session_kind x11 (docs/other-simulators.md; a study installs what its own kind needs).
# Clients we did not write: Firefox ESR (the Firefox browser tests, driven over WebDriver BiDi), TigerVNC's viewer
# under Xvfb with xdotool for keys, and Debian's stock noVNC 1.3 page (bench_network's JPEG-only browser row).
[ "$with_browser" = 1 ] && packages+=(chromium clang libclang-rt-14-dev haproxy
  libmujoco-dev tigervnc-standalone-server mesa-utils x11-apps x11-utils libx11-dev
  firefox-esr tigervnc-viewer xvfb xdotool novnc)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The page's npm packages, exactly as locked (noVNC; playwright-core drives Debian's Chromium in tests,
# puppeteer-core Debian's Firefox ESR).
if [ ! -f web/node_modules/.package-lock.json ] || ! cmp -s web/package-lock.json web/.installed-lock.json; then
  echo "setup: npm ci in web/"
  npm ci --prefix web --no-audit --no-fund --loglevel=error
  cp web/package-lock.json web/.installed-lock.json
fi

# Configure once; later builds re-run CMake by themselves when a CMakeLists.txt changes, so a second start of a
# demo goes straight to the (empty) build. New -D options configure again.
if [ ! -f "$build_dir/CMakeCache.txt" ] || [ ${#cmake_args[@]} -gt 0 ]; then
  generator=()
  command -v ninja >/dev/null 2>&1 && [ ! -f "$build_dir/CMakeCache.txt" ] && generator=(-G Ninja)
  cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${cmake_args[@]}"
fi
cmake --build "$build_dir" -j "$(nproc)" "${targets[@]}"
