#!/usr/bin/env bash
# Create .venv (if needed) and install dcee with its development tools into it.
set -euo pipefail
cd "$(dirname "$0")/.."
# scripts/test.sh sets this once both venvs are installed, so that the steps it runs side by
# side do not install into the same source tree at once
if [ "${DCEE_SETUP_DONE:-0}" = 1 ]; then exit 0; fi
source scripts/venv.sh
install_into .venv -e ".[dev,docs]"
