#!/usr/bin/env bash
# Installs gyrofx's C library under a prefix, for C, C++ and DPI-C testbenches outside this
# repository: PREFIX/lib/libgyrofx_capi.{a,so}, PREFIX/include/gyrofx.h and
# PREFIX/lib/pkgconfig/gyrofx_capi.pc, so that
#
#   PKG_CONFIG_PATH=PREFIX/lib/pkgconfig cc my_bench.c $(pkg-config --cflags --libs --static gyrofx_capi)
#
# builds a program against it (`--static` adds the system libraries the static archive needs;
# where the linker takes the shared library, run the program with PREFIX/lib on
# LD_LIBRARY_PATH).
#
#   scripts/install-capi.sh PREFIX [--from DIR] [--force]
#
# Builds the library (cargo build --release -p gyrofx-capi) unless --from names a folder that
# holds libgyrofx_capi.a (and .so) already. A file already at a destination is refused unless
# --force: the script replaces only what you say it may.
set -euo pipefail
cd "$(dirname "$0")/.."
usage() { echo "usage: scripts/install-capi.sh PREFIX [--from DIR] [--force]" >&2; exit 2; }
[ $# -ge 1 ] || usage
prefix="$1"; shift
from=""; force=0
while [ $# -gt 0 ]; do
    case "$1" in
        --from) [ $# -ge 2 ] || usage; from="$2"; shift 2 ;;
        --force) force=1; shift ;;
        *) usage ;;
    esac
done
case "$prefix" in /*) ;; *) prefix="$PWD/$prefix" ;; esac
if [ -e "$prefix" ] && [ ! -d "$prefix" ]; then
    echo "FAIL: PREFIX $prefix exists and is not a folder" >&2
    exit 1
fi
if [ -z "$from" ]; then
    cargo build --release -p gyrofx-capi
    from="${CARGO_TARGET_DIR:-target}/release"
fi
[ -f "$from/libgyrofx_capi.a" ] || { echo "FAIL: $from/libgyrofx_capi.a is missing" >&2; exit 1; }
version="$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
files=("lib/libgyrofx_capi.a" "include/gyrofx.h" "lib/pkgconfig/gyrofx_capi.pc")
[ -f "$from/libgyrofx_capi.so" ] && files+=("lib/libgyrofx_capi.so")
if [ "$force" -eq 0 ]; then
    for file in "${files[@]}"; do
        if [ -e "$prefix/$file" ]; then
            echo "FAIL: $prefix/$file exists; remove it or pass --force to replace it" >&2
            exit 1
        fi
    done
fi
mkdir -p "$prefix/lib/pkgconfig" "$prefix/include"
install -m 644 "$from/libgyrofx_capi.a" "$prefix/lib/libgyrofx_capi.a"
[ -f "$from/libgyrofx_capi.so" ] && install -m 755 "$from/libgyrofx_capi.so" "$prefix/lib/libgyrofx_capi.so"
install -m 644 capi/include/gyrofx.h "$prefix/include/gyrofx.h"
sed -e "s|@PREFIX@|$prefix|" -e "s|@VERSION@|$version|" capi/gyrofx_capi.pc.in \
    > "$prefix/lib/pkgconfig/gyrofx_capi.pc"
echo "installed gyrofx_capi $version under $prefix"
