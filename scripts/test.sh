#!/usr/bin/env bash
# Set up, then lint (ruff), run the test suite (pytest), the ROS 2 tests in .venv-ros
# (scripts/test-ros.sh) and build the documentation site with
# its executed examples (mkdocs --strict: any warning fails).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
.venv/bin/ruff check src tests examples studies scripts ros
.venv/bin/ruff format --check src tests examples studies scripts ros
.venv/bin/python -m pytest -q "$@"
bash scripts/test-ros.sh
DOCS_OUT=${DOCS_OUT:-$(mktemp -d)/site} bash scripts/docs.sh
