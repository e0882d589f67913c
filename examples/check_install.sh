#!/usr/bin/env bash
# Installs a build (cmake --install BUILD --prefix TMP) and builds examples/embed.c against the
# installed package alone, twice: with pkg-config (docs/embedding.md's line) and with CMake's
# find_package(pfsph) (examples/CMakeLists.txt); runs both, which must print the same.
# usage: examples/check_install.sh BUILD_DIR
set -euo pipefail
build=${1:?usage: check_install.sh BUILD_DIR}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
for f in lib/libpfsph.a include/pfsph.h include/pfsph/config.h lib/cmake/pfsph/pfsphConfig.cmake \
         lib/pkgconfig/pfsph.pc; do
  test -f "$tmp/prefix/$f" || { echo "check_install: $f was not installed" >&2; exit 1; }
done
# the installed headers are pfsph.h and its config, nothing of src/
if [ "$(find "$tmp/prefix/include" -type f | wc -l)" != 2 ]; then
  echo "check_install: more than pfsph.h and pfsph/config.h installed:" >&2
  find "$tmp/prefix/include" -type f >&2
  exit 1
fi
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
# shellcheck disable=SC2046 # pkg-config's flags are separate words
cc -std=c11 -Wall -Wextra -Werror "$here/embed.c" -o "$tmp/embed" \
  $(PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig" pkg-config --cflags --libs --static pfsph)
"$tmp/embed" >"$tmp/out.txt"
cmake -S "$here" -B "$tmp/cmake" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/cmake" >/dev/null
"$tmp/cmake/embed" >"$tmp/out_cmake.txt"
if ! cmp -s "$tmp/out.txt" "$tmp/out_cmake.txt"; then
  echo "check_install: the pkg-config and the CMake build of embed.c print different things:" >&2
  diff "$tmp/out.txt" "$tmp/out_cmake.txt" >&2 || true
  exit 1
fi
cat "$tmp/out.txt"
echo "check_install: embed.c built against the installed package (pkg-config, CMake find_package) and ran"
