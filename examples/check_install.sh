#!/usr/bin/env bash
# Installs a build (cmake --install BUILD --prefix TMP), compiles examples/embed.c against the
# installed package alone with pkg-config and runs it: the embedding path of docs/embedding.md.
# usage: examples/check_install.sh BUILD_DIR
set -euo pipefail
build=${1:?usage: check_install.sh BUILD_DIR}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# the installed tree has pfsph.h and its config, nothing of src/
test -f "$tmp/prefix/include/pfsph.h" && test ! -e "$tmp/prefix/include/pfsph/sim.h"
export PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig"
cc -std=c11 -Wall -Wextra -Werror "$here/embed.c" -o "$tmp/embed" $(pkg-config --cflags --libs --static pfsph)
OMP_NUM_THREADS=2 "$tmp/embed" >"$tmp/out.txt"
cat "$tmp/out.txt"
echo "check_install: embed.c built against the installed package with pkg-config and ran"
