#!/usr/bin/env bash
# Set up, then lint (ruff), compile the kernels (scripts/warm_kernels.py), run the test suite
# (pytest on two processes, one per core of the 2-core machine the README's times are measured
# on; PYTEST_WORKERS overrides), the ROS 2 tests in .venv-ros (scripts/test-ros.sh) and build the
# documentation site with its executed examples (mkdocs --strict: any warning fails) and its
# browser check. Side by side, to keep both cores busy: .venv-ros installs while the kernels
# compile and the suite runs, and the documentation builds while the ROS 2 tests run (they wait
# mostly on message round trips); each part's output is printed whole, and any failure fails
# the run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
logs=$(mktemp -d)
bash scripts/setup-ros.sh >"$logs/setup-ros.log" 2>&1 &
setup_ros=$!
.venv/bin/ruff check src tests examples studies scripts ros
.venv/bin/ruff format --check src tests examples studies scripts ros
# the numerical kernels compiled into numba's cache once (scripts/warm_kernels.py says why;
# seconds when the cache is filled already): what every search uses beside the ROS 2 install,
# then the rest on both cores
.venv/bin/python scripts/warm_kernels.py core
.venv/bin/python scripts/warm_kernels.py 0 2 &
warm=$!
.venv/bin/python scripts/warm_kernels.py 1 2
wait "$warm"
.venv/bin/python -m pytest -q -n "${PYTEST_WORKERS:-2}" "$@"
if ! wait "$setup_ros"; then
  cat "$logs/setup-ros.log" >&2
  echo "test: setting up .venv-ros failed" >&2
  exit 1
fi
export DCEE_SETUP_DONE=1
DOCS_OUT=${DOCS_OUT:-$logs/site} bash scripts/docs.sh >"$logs/docs.log" 2>&1 &
docs=$!
ros_status=0
bash scripts/test-ros.sh || ros_status=$?
docs_status=0
wait "$docs" || docs_status=$?
cat "$logs/docs.log"
if [ "$ros_status" -ne 0 ] || [ "$docs_status" -ne 0 ]; then
  echo "test: ROS 2 tests exit $ros_status, documentation build exit $docs_status" >&2
  exit 1
fi
