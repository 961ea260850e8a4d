#!/usr/bin/env bash
# Set up, then lint (ruff), compile the kernels (scripts/warm_kernels.py), run the test suite
# (pytest on two processes, one per core of the 2-core machine the README's times are measured
# on; PYTEST_WORKERS overrides), the ROS 2 tests in .venv-ros (scripts/test-ros.sh) and build the
# documentation site with its executed examples (mkdocs --strict: any warning fails) and its
# browser check. Side by side, to keep both cores busy: .venv-ros installs while the kernels
# compile, then the suite, the documentation build and the ROS 2 tests share the cores (the
# suite's two processes finish unevenly, and the ROS 2 tests wait mostly on message round trips,
# with generous deadlines). Each part's output is printed whole, after it, and any failure
# fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."
# each part's end, in seconds since the start (what the README's time is made of)
took() { echo "test: $1 done at ${SECONDS} s"; }
bash scripts/setup.sh
took "set-up"
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
took "lint and kernels"
# three jobs on two cores: one compute thread in each process (tests/conftest.py says why),
# the documentation's executed examples and the ROS 2 node included
export NUMBA_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
# .venv is complete: the documentation build must not install into it again
DCEE_SETUP_DONE=1 DOCS_OUT=${DOCS_OUT:-$logs/site} bash scripts/docs.sh >"$logs/docs.log" 2>&1 &
docs=$!
# the ROS 2 tests beside the suite, once .venv-ros is installed (it installed while the
# kernels compiled)
if wait "$setup_ros"; then
  took "ROS 2 set-up"
  DCEE_SETUP_DONE=1 bash scripts/test-ros.sh >"$logs/ros.log" 2>&1 &
  ros=$!
else
  cat "$logs/setup-ros.log" >"$logs/ros.log"
  echo "test: setting up .venv-ros failed" >>"$logs/ros.log"
  (exit 1) &
  ros=$!
fi
pytest_status=0
.venv/bin/python -m pytest -q -n "${PYTEST_WORKERS:-2}" "$@" || pytest_status=$?
took "pytest"
ros_status=0
wait "$ros" || ros_status=$?
cat "$logs/ros.log"
took "ROS 2 tests"
docs_status=0
wait "$docs" || docs_status=$?
cat "$logs/docs.log"
took "documentation"
if [ "$pytest_status" -ne 0 ] || [ "$ros_status" -ne 0 ] || [ "$docs_status" -ne 0 ]; then
  echo "test: pytest exit $pytest_status, ROS 2 tests exit $ros_status," \
    "documentation build exit $docs_status" >&2
  exit 1
fi
