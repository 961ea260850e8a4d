#!/usr/bin/env bash
# Set up (with the documentation tools), then build the documentation site into $DOCS_OUT
# (default: site/). Warnings are errors (mkdocs strict mode); the examples are executed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
MPLBACKEND=Agg .venv/bin/mkdocs build --strict --clean --site-dir "${DOCS_OUT:-site}"
# equations typeset and no console error, in headless Chromium with the network off (installed
# here where missing: a check that skips itself is no check)
bash scripts/setup-browser.sh
.venv/bin/python scripts/docs_browser_check.py "${DOCS_OUT:-site}"
echo "documentation: ${DOCS_OUT:-site}/index.html"
