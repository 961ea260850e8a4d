#!/usr/bin/env bash
# Reproduce a published table: `bash studies/run.sh NAME` runs the study's recipe
# (studies/recipes/NAME.toml) with `python -m studies NAME`: its campaigns (resumable: rerun to
# finish; finished searches are skipped), then the steps that write its tables. `--list` lists
# the studies, `--pins` the historical pins (studies/pins.toml), `NAME --dry-run` prints the
# commands without running them. studies/README.md says which table each study makes.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x .venv/bin/python ] || bash scripts/setup.sh
exec .venv/bin/python -m studies "$@"
