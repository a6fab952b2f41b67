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
# --force: the script replaces only what you say it may. Every file is written beside its
# destination first and renamed into place only when all are written, so an error or a signal
# leaves the prefix as it was (the staged copies removed, the folders it made removed when empty).
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
made=()
for folder in "$prefix" "$prefix/lib" "$prefix/lib/pkgconfig" "$prefix/include"; do
    [ -d "$folder" ] || made+=("$folder")
done
staged=()
finished=0
cleanup() {
    for file in "${staged[@]}"; do rm -f "$file"; done
    if [ "$finished" -eq 0 ]; then
        for ((i = ${#made[@]} - 1; i >= 0; i--)); do rmdir "${made[$i]}" 2>/dev/null || true; done
    fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM
mkdir -p "$prefix/lib/pkgconfig" "$prefix/include"
# stage SOURCE MODE DESTINATION: the file written as DESTINATION.gyrofx-install.<pid>.
stage() {
    local copy="$3.gyrofx-install.$$"
    staged+=("$copy")
    install -m "$2" "$1" "$copy"
}
stage "$from/libgyrofx_capi.a" 644 "$prefix/lib/libgyrofx_capi.a"
[ -f "$from/libgyrofx_capi.so" ] && stage "$from/libgyrofx_capi.so" 755 "$prefix/lib/libgyrofx_capi.so"
stage capi/include/gyrofx.h 644 "$prefix/include/gyrofx.h"
pc="$(mktemp)"
staged+=("$pc")
sed -e "s|@PREFIX@|$prefix|" -e "s|@VERSION@|$version|" capi/gyrofx_capi.pc.in > "$pc"
stage "$pc" 644 "$prefix/lib/pkgconfig/gyrofx_capi.pc"
if [ -n "${GYROFX_INSTALL_FAIL_BEFORE_RENAME:-}" ]; then
    echo "FAIL: stopped before the renames (GYROFX_INSTALL_FAIL_BEFORE_RENAME, for the tests)" >&2
    exit 1
fi
for file in "${files[@]}"; do
    mv -f "$prefix/$file.gyrofx-install.$$" "$prefix/$file"
done
finished=1
echo "installed gyrofx_capi $version under $prefix"
