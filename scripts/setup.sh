#!/usr/bin/env bash
# Installs everything tetstream needs on a fresh Debian 12 machine and fetches the third-party
# sources the wasm build compiles (Dear ImGui, zstd) into build/_deps (git-ignored).
# Idempotent: a second run only checks. Only Debian's archive and npm are used.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
DEPS=$ROOT/build/_deps

APT_PACKAGES=(
  build-essential cmake pkg-config clang-format
  emscripten                       # wasm toolchain (3.1.6), brings node-acorn, binaryen, lld
  libglm-dev libzstd-dev zstd zlib1g-dev libxxhash-dev
  libpugixml-dev libcli11-dev nlohmann-json3-dev libgtest-dev libstb-dev
  chromium                         # headless browser tests
  nginx wrk                        # tests against real nginx (server/nginx.conf); server load test
  openssl                          # certificates for the HTTPS and HTTP/2 tests and bench
  libhdf5-dev libnetcdf-dev libexodusii-dev libcgns-dev   # Exodus II, CGNS, XDMF and VTKHDF readers
  python3-vtk9 python3-meshio python3-netcdf4 python3-h5py cgns-convert  # independent writers for their tests
  openmpi-bin libopenmpi-dev       # packing on several processes (mpirun tetstream pack)
)

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done

need_src=0
[ -f "$DEPS/imgui/imgui.cpp" ] || need_src=1
[ -f "$DEPS/zstd/lib/zstd.h" ] || need_src=1

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if [ ${#missing[@]} -gt 0 ] || [ $need_src = 1 ]; then
  if [ ! -f /etc/apt/sources.list.d/debian-src.sources ]; then
    echo "setup: adding Debian source-package entry (for imgui and zstd sources)"
    as_root tee /etc/apt/sources.list.d/debian-src.sources >/dev/null <<'SRC'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  fi
  echo "setup: apt-get update"
  as_root apt-get update -qq
fi

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  # Debian's nginx package starts a system service on port 80 when installed. tetstream does
  # not use it (tests start their own nginx on a free port): stop the one we just installed.
  if [[ " ${missing[*]} " == *" nginx "* ]]; then
    if command -v systemctl >/dev/null && systemctl is-active --quiet nginx 2>/dev/null; then
      as_root systemctl disable --now nginx >/dev/null 2>&1 || true
    elif [ -s /run/nginx.pid ]; then
      as_root /usr/sbin/nginx -s quit 2>/dev/null || true
    fi
  fi
fi

fetch_src() { # fetch_src SRCPKG DESTNAME
  local tmp; tmp=$(mktemp -d)
  (cd "$tmp" && apt-get source -qq --download-only "$1" >/dev/null 2>&1)
  local dsc; dsc=$(ls "$tmp"/*.dsc | head -n1)
  rm -rf "$DEPS/$2"
  dpkg-source -q -x "$dsc" "$DEPS/$2" >/dev/null
  rm -rf "$tmp"
}
mkdir -p "$DEPS"
if [ ! -f "$DEPS/imgui/imgui.cpp" ]; then echo "setup: fetching Dear ImGui source (Debian imgui)"; fetch_src imgui imgui; fi
if [ ! -f "$DEPS/zstd/lib/zstd.h" ]; then echo "setup: fetching zstd source (Debian libzstd)"; fetch_src libzstd zstd; fi

# Header-only pieces for the wasm build: never put /usr/include itself on emcc's path.
mkdir -p "$DEPS/include"
[ -e "$DEPS/include/glm" ] || ln -s /usr/include/glm "$DEPS/include/glm"
[ -e "$DEPS/include/nlohmann" ] || ln -s /usr/include/nlohmann "$DEPS/include/nlohmann"
[ -e "$DEPS/include/xxhash.h" ] || ln -s /usr/include/xxhash.h "$DEPS/include/xxhash.h"
[ -e "$DEPS/include/stb" ] || ln -s /usr/include/stb "$DEPS/include/stb"

if [ ! -d node_modules/playwright-core ] || [ package.json -nt node_modules/.package-lock.json ]; then
  echo "setup: npm install"
  npm install --no-audit --no-fund --loglevel=error >/dev/null
fi
echo "setup: ok"
