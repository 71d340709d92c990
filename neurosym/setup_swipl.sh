#!/usr/bin/env bash
# Make sure a SWI-Prolog >= 9.1.12 (what janus-swi needs) is available to the
# virtual environment given as $1, and print the path of its `swipl` binary.
# `neurosym setup-prolog` runs it (the wheel ships it) when it finds no such Prolog.
#
# 1. A `swipl` on PATH that is new enough is used as it is.
# 2. Otherwise SWI-Prolog 9.2.9 is built from the Debian source tarball into
#    $VENV/swipl (about 70 s on 2 cores), once; later runs find it there.
# The tarball is fetched through the Debian mirror named by this machine's own
# apt sources and checked against its sha256 before anything is built.
set -euo pipefail

VENV=${1:?usage: setup_swipl.sh VENV}
VENV=$(cd "$VENV" && pwd)
VERSION=9.2.9
TARBALL="swi-prolog_${VERSION}+dfsg.orig.tar.gz"
SHA256=6d6f2dd6e4558bccb7c87cc7a5cbcf582503384a5fa890efba0ae91a0aaf2258
PREFIX="$VENV/swipl"
MIN_VERSION=90112   # 9.1.12, as SWI-Prolog's current_prolog_flag(version) numbers it

log() { echo "setup_swipl: $*" >&2; }

swipl_version() {  # print the numeric version of the swipl binary $1, or nothing
  "$1" --dump-runtime-variables >/dev/null 2>&1 || return 0
  "$1" -g 'current_prolog_flag(version,V),write(V),nl' -t halt 2>/dev/null || true
}

# Already built here?
if [ -x "$PREFIX/bin/swipl" ] && [ -n "$(swipl_version "$PREFIX/bin/swipl")" ]; then
  echo "$PREFIX/bin/swipl"; exit 0
fi

# A new enough swipl on PATH?
if command -v swipl >/dev/null 2>&1; then
  v=$(swipl_version "$(command -v swipl)")
  if [ -n "$v" ] && [ "$v" -ge "$MIN_VERSION" ]; then
    command -v swipl; exit 0
  fi
  log "swipl on PATH is version ${v:-unknown}; janus-swi needs >= 9.1.12, building $VERSION"
fi

# Build dependencies from apt, only those missing.
need=()
command -v cmake >/dev/null || need+=(cmake)
command -v ninja >/dev/null || need+=(ninja-build)
command -v cc >/dev/null || need+=(gcc)
command -v curl >/dev/null || need+=(curl)
for pkg in libgmp-dev libreadline-dev zlib1g-dev libncurses-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  log "installing build dependencies: ${need[*]}"
  if [ "$(id -u)" -eq 0 ]; then SUDO=; else SUDO=sudo; fi
  $SUDO apt-get update -qq
  $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null
fi

# The Debian mirror this machine's apt already uses.
mirror=$(grep -hsE '^\s*URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null \
           | awk '{print $2}' | grep -v -- '-security' | head -n1 || true)
if [ -z "$mirror" ]; then
  mirror=$(grep -hsE '^\s*deb\s' /etc/apt/sources.list 2>/dev/null \
             | awk '{for (i=2;i<=NF;i++) if ($i ~ /^https?:/) {print $i; exit}}' \
             | grep -v -- '-security' | head -n1 || true)
fi
if [ -z "$mirror" ]; then
  log "error: no Debian mirror found in /etc/apt/sources.list(.d); install SWI-Prolog >= 9.1.12 and put swipl on PATH"
  exit 1
fi
mirror=${mirror%/}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cache="$VENV/.cache"
mkdir -p "$cache"
if [ ! -f "$cache/$TARBALL" ] || ! echo "$SHA256  $cache/$TARBALL" | sha256sum -c --status; then
  log "fetching $TARBALL"
  curl -fsSL --retry 3 -o "$cache/$TARBALL.part" "$mirror/pool/main/s/swi-prolog/$TARBALL"
  mv "$cache/$TARBALL.part" "$cache/$TARBALL"
fi
if ! echo "$SHA256  $cache/$TARBALL" | sha256sum -c --status; then
  log "error: checksum mismatch for $TARBALL (expected sha256 $SHA256)"
  rm -f "$cache/$TARBALL"
  exit 1
fi

log "building SWI-Prolog $VERSION into $PREFIX"
tar -xzf "$cache/$TARBALL" -C "$work"
src=$(find "$work" -maxdepth 1 -mindepth 1 -type d | head -n1)
cmake -S "$src" -B "$work/build" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$PREFIX" \
  -DSWIPL_PACKAGE_LIST="clib;plunit;swipy;readline" \
  -DINSTALL_DOCUMENTATION=OFF -DBUILD_TESTING=OFF \
  -DUSE_TCMALLOC=OFF >"$work/cmake.log" 2>&1 || { tail -n 30 "$work/cmake.log" >&2; exit 1; }
ninja -C "$work/build" >"$work/build.log" 2>&1 || { tail -n 40 "$work/build.log" >&2; exit 1; }
ninja -C "$work/build" install >"$work/install.log" 2>&1 || { tail -n 20 "$work/install.log" >&2; exit 1; }
v=$(swipl_version "$PREFIX/bin/swipl")
if [ -z "$v" ]; then
  log "error: the freshly built $PREFIX/bin/swipl does not run"
  exit 1
fi
"$PREFIX/bin/swipl" --version >&2
echo "$PREFIX/bin/swipl"
