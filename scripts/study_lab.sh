#!/usr/bin/env bash
# The paper's indoor experiment (section 6) in simulation: both starts, seven unknowns, five
# planners x 10 repeats at paper scale (20,000 particles): with the unicycle robot (time per
# move from its dynamics) and with the paper's idealised grid agent against the isotropic truth,
# and with the unicycle robot against the turbulent filament truth (the fans of the paper's
# room) with the fluctuation likelihood. Resumable: rerun to finish.
# Tables: scripts/lab_table.py; figures: dcee report.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
W=${WORKERS:-2}
S=dcee,dcee-cl,entrotaxis,infotaxis,mpc
$D bench --suite lab-robot --repeats 10 --strategies $S --workers "$W" --out results/lab-robot
$D bench --suite lab --repeats 10 --strategies $S --workers "$W" --out results/lab-grid
$D bench --suite lab-robot --repeats 10 --strategies $S --workers "$W" --truth filament \
    --likelihood fluctuation --out results/lab-robot-filament
for c in lab-robot lab-grid lab-robot-filament; do
    $D report results/$c --out results/report-$c
done
.venv/bin/python scripts/lab_table.py results/lab-robot results/lab-grid
