#!/usr/bin/env bash
# Issue 32, item 2: what a measured wind buys in the full-unknown study. dcee-cl, all eight
# parameters unknown, on held-out-24 (random:1000 ... random:1023, reporting range; a small
# sample) x seeds 0-3, 10,000 particles, with and without the anemometer (1 Hz, 0.5 m/s and
# 10 deg noise), the same seeds: paired by (configuration, seed). Resumable.
# Table: studies/anemometer_table.py results/anemometer-off results/anemometer-on
#   --vague results/anemometer-off-vague results/anemometer-on-vague
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
C="--suite held-out-24 --repeats 4 --particles 10000 --unknown full --strategies dcee-cl --allow-code-change"
$D bench $C --out results/anemometer-off
$D bench $C --set anemometer.enabled=true --out results/anemometer-on
# the same with no prior knowledge of the wind direction (phi uniform over the circle), seeds
# 0-1: what the anemometer buys a robot that does not know where the wind comes from
V="--suite held-out-24 --repeats 2 --particles 10000 --unknown full --strategies dcee-cl --allow-code-change"
U='prior.phi={kind="uniform",low=-180.0,high=180.0}'
$D bench $V --set "$U" --out results/anemometer-off-vague
$D bench $V --set "$U" --set anemometer.enabled=true --out results/anemometer-on-vague
