#!/usr/bin/env bash
# The robots-vs-time study (issue 16): 1, 2 and 3 robots sharing one belief, infotaxis and
# dcee-cl, the paper suite with the wind known, same seeds. Resumable: rerun to finish; each
# command skips the searches already done. Tables: studies/team_table.py (README, docs/results.md).
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
# preliminary, small: 10,000 particles, 3 repeats (36 searches per planner and team size)
for K in 1 2 3; do
    $D bench --suite paper --repeats 3 --particles 10000 --agents "$K" \
        --strategies infotaxis,dcee-cl --out "results/team10k-a$K" --allow-code-change
done
.venv/bin/python studies/team_table.py results/team10k-a1 results/team10k-a2 results/team10k-a3
# paper scale: 20,000 particles, 10 repeats; one robot is results/paper-source-cl2 (same seeds)
# (2026-11-22: 2 robots 37 min, 3 robots about 75 min on two cores shared with other work)
for K in 2 3; do
    $D bench --suite paper --repeats 10 --agents "$K" --strategies infotaxis,dcee-cl \
        --out "results/team-a$K" --allow-code-change
done
.venv/bin/python studies/team_table.py results/paper-source-cl2 results/team-a2 results/team-a3
