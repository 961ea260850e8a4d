#!/usr/bin/env bash
# Issue 29: both turbulent truths (the filament and the independent puff plume), all eight
# parameters unknown, the fluctuation likelihood, dcee-cl and infotaxis, on held-out
# configurations (random:1000-1023, a small sample: 24 searches per planner and truth).
# SUITE (default held-out-24), WORKERS (1), OUT_SUFFIX (appended to the folder), STRATEGIES
# (default dcee-cl,infotaxis) and TRUTHS (default "puffs filament") select the study; further arguments go to dcee bench (e.g. --set
# agent.climb=0.0).
# Resumable: rerun to finish; then `dcee report results/turbulent-<truth>-<suite><suffix>`.
set -euo pipefail
cd "$(dirname "$0")/.."
SUITE=${SUITE:-held-out-24}
for truth in ${TRUTHS:-puffs filament}; do
  .venv/bin/dcee bench --suite "$SUITE" --strategies "${STRATEGIES:-dcee-cl,infotaxis}" --repeats 1 \
    --unknown full --likelihood fluctuation --truth "$truth" --particles 10000 \
    --workers "${WORKERS:-1}" --out "results/turbulent-$truth-$SUITE${OUT_SUFFIX:-}" "$@"
done
