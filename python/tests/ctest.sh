#!/bin/sh
# CTest's entry to the Python package's tests (label python): pytest over python/tests with the
# build's libpfsph.so ($PFSPH_LIBRARY, the target pfsph_shared) and the package from the source
# tree. Exit 77 (Skipped) without a shared library (configure with -DPFSPH_SHARED=ON) or without
# a Python that has numpy, cffi and pytest (Debian: python3-numpy python3-cffi python3-pytest).
# The interpreter: $PFSPH_PYTHON, else the first python3 on PATH that has them, else /usr/bin/python3.
here=$(cd "$(dirname "$0")" && pwd)
if [ -z "$PFSPH_LIBRARY" ] || [ ! -f "$PFSPH_LIBRARY" ]; then
  echo "python tests skipped: no libpfsph.so in this build (configure with -DPFSPH_SHARED=ON; not in sanitized builds)"
  exit 77
fi
py=""
for c in "$PFSPH_PYTHON" python3 /usr/bin/python3; do
  [ -n "$c" ] || continue
  if "$c" -c "import numpy, cffi, pytest" >/dev/null 2>&1; then py=$c; break; fi
done
if [ -z "$py" ]; then
  echo "python tests skipped: no python3 with numpy, cffi and pytest (Debian: python3-numpy python3-cffi python3-pytest)"
  exit 77
fi
echo "python: $("$py" -c 'import sys; print(sys.executable, sys.version.split()[0])'), library $PFSPH_LIBRARY"
PYTHONPATH="$here/..${PYTHONPATH:+:$PYTHONPATH}" exec "$py" -m pytest -p no:cacheprovider -q -rs --durations=6 "$here" "$@"
