#!/usr/bin/env bash
# The turbulent-plume studies with the turbulence level estimated online (issue 12: the calm
# model beside the fluctuation model, estimator.calm_prior) and the defaults chosen by search
# (near_source_length 10 m). Resumable: rerun to finish. Results land in results/ (not
# versioned); the tables are in the README and docs/results.md.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
FIL="--suite paper --unknown full --truth filament --likelihood fluctuation"
# the done-when check: 12 configurations, one repeat, 10,000 particles
$D bench $FIL --strategies infotaxis --repeats 1 --particles 10000 --out results/filament-calm-10k
# what it costs on the isotropic truth (wind known), 12 × 10 at paper scale
$D bench --suite paper --strategies infotaxis --repeats 10 --likelihood fluctuation --out results/paper-source-calm
# the filament study at paper scale (20,000 particles), infotaxis 12 × 10
$D bench $FIL --strategies infotaxis --repeats 10 --out results/filament-calm
# the other strategies on the filament truth: 3 repeats first, then the full 10 (infotaxis ran
# before `dcee report` learnt the model-selection table, a change that decides no result; the
# campaign records both code versions)
O="$FIL --strategies dcee,mpc,entrotaxis,dcee-cl --allow-code-change --out results/filament-calm"
$D bench $O --repeats 3
$D bench $O --repeats 10
