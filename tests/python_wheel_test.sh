#!/bin/sh
# tests/python_wheel_test.sh SOURCE PYTHON RAYSTREAM — the issue's check, as a new user runs it:
# a fresh venv, `pip install SOURCE` (pyproject.toml: scikit-build-core builds the module from
# the project's CMakeLists.txt), then
#   python -c "import raystream, numpy; a = numpy.asarray(raystream.render('builtin:cornell',
#              spp=16)); print(a.shape, a.dtype)"
# must print (600, 600, 3) float32, and tests/python passes against the installed module.
# The venv sees the system's numpy and pytest (python3-numpy, python3-pytest); pip fetches
# scikit-build-core from PyPI: where PyPI cannot be reached the test is skipped (77), saying so.
# CUDA is left out of this build (RS_CUDA=OFF: the CPU image is the same, and CI keeps its time).
set -eu
src="$1"
py="$2"
cli="$3"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() {
    echo "python_wheel_test: $*" >&2
    exit 1
}
"$py" -m venv --system-site-packages "$tmp/venv" >"$tmp/venv.log" 2>&1 ||
    fail "python -m venv failed (python3-venv): $(tail -n 1 "$tmp/venv.log")"
vpy="$tmp/venv/bin/python"
if ! "$vpy" -m pip download -q --no-deps -d "$tmp/dl" scikit-build-core >"$tmp/dl.log" 2>&1; then
    echo "python_wheel_test: skipped: PyPI cannot be reached for scikit-build-core" \
        "($(tail -n 1 "$tmp/dl.log"))"
    exit 77
fi
if ! "$vpy" -c "import numpy, pytest" 2>/dev/null; then
    "$vpy" -m pip install -q numpy pytest >"$tmp/np.log" 2>&1 ||
        fail "numpy and pytest: neither installed (python3-numpy, python3-pytest) nor fetched"
fi
CMAKE_BUILD_PARALLEL_LEVEL=$(nproc) "$vpy" -m pip install -q "$src" \
    --config-settings=cmake.define.RS_CUDA=OFF >"$tmp/pip.log" 2>&1 ||
    fail "pip install failed: $(tail -n 20 "$tmp/pip.log")"
cd "$tmp"
got=$("$vpy" -c "import raystream, numpy; a = numpy.asarray(raystream.render('builtin:cornell', spp=16)); print(a.shape, a.dtype)")
[ "$got" = "(600, 600, 3) float32" ] || fail "printed '$got', not '(600, 600, 3) float32'"
where=$("$vpy" -c "import raystream; print(raystream.__file__)")
case "$where" in
"$tmp/venv/"*) ;;
*) fail "raystream was imported from $where, not the venv" ;;
esac
RS_BINARY="$cli" "$vpy" -m pytest -q -p no:cacheprovider "$src/tests/python" ||
    fail "tests/python failed against the installed module"
echo "python_wheel_test: pip install . in a fresh venv; '$got'; tests/python pass"
