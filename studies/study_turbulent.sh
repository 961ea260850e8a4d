#!/usr/bin/env bash
# The turbulent-plume studies (issue 12). Resumable: rerun to finish; each command skips the
# searches already done. Results land in results/ (not versioned); tables are in the README.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
FIL="--suite paper --unknown full --truth filament --likelihood fluctuation"
# the done-when check: 12 configurations, one repeat, 10,000 particles
$D bench $FIL --strategies infotaxis --repeats 1 --particles 10000 --out results/filament-fluct-10k
# the filament study at paper scale (20,000 particles): infotaxis 12 × 10 first
$D bench $FIL --strategies infotaxis --repeats 10 --out results/filament-fluct
# what the fluctuation likelihood costs on the isotropic truth (wind known): 3 repeats first
$D bench --suite paper --strategies infotaxis --repeats 3 --likelihood fluctuation --out results/paper-source-fluct
# what each part bought (infotaxis, 12 × 3, 10,000 particles), each part taken away alone
A="$FIL --strategies infotaxis --repeats 3 --particles 10000"
$D bench $A --out results/ablation/all
$D bench $A --set sensor.average=0 --out results/ablation/no-averaging
$D bench $A --set estimator.near_source_length=0 --out results/ablation/constant-intermittency
$D bench $A --set estimator.meander=0 --out results/ablation/no-meander
$D bench $A --set search.global_share=0 --out results/ablation/random-walk-move
$D bench --suite paper --unknown full --truth filament --strategies infotaxis --repeats 3 --particles 10000 --out results/ablation/paper-likelihood
# the other strategies on the filament truth: 3 repeats first, then the full 10
$D bench $FIL --strategies entrotaxis,dcee,mpc --repeats 3 --out results/filament-fluct
$D bench $FIL --strategies entrotaxis,dcee,mpc --repeats 10 --out results/filament-fluct
$D bench --suite paper --strategies infotaxis --repeats 10 --likelihood fluctuation --out results/paper-source-fluct
