#!/bin/sh
# tests/python/run.sh PYTHON BUILD/python RAYSTREAM — tests/python against the module as built
# (CTest python_test).  Skipped (77) with a line where numpy or pytest is missing for PYTHON
# (scripts/install-deps.sh installs python3-numpy and python3-pytest).
set -eu
py="$1"
if ! "$py" -c "import numpy, pytest" 2>/dev/null; then
    echo "python_test: skipped: $py has no numpy or pytest (apt-get install python3-numpy python3-pytest)"
    exit 77
fi
PYTHONPATH="$2" RS_BINARY="$3" exec "$py" -m pytest -q -p no:cacheprovider "$(dirname "$0")"
