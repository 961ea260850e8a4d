#!/usr/bin/env bash
# Issue 31, item 8: the stop-when-localised rule. dcee-cl flies its whole budget on the tuning
# range (random-tune, random:1 ... random:40) and on the reporting range (held-out, K >= 1000);
# studies/stop_rule_table.py replays the rule on every recorded step (exact: the rule reads
# only the recorded posterior spread and time, and a search that stops makes no further
# reading). The rule's threshold and hold were chosen on the tuning folders only; the tables
# in docs/results.md headed "held-out" come from the reporting folders. Resumable.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
# dcee-cl looked one move ahead before search.lookahead (2026-11-29): pinned so this reproduces
C="--repeats 1 --particles 10000 --strategies dcee-cl --allow-code-change --set search.lookahead=1"
# tuning range
$D bench --suite random-tune $C --unknown source --out results/stop-tune-wind-known
$D bench --suite random-tune $C --unknown full --out results/stop-tune-full
$D bench --suite random-tune-12 $C --unknown full --truth filament --likelihood fluctuation \
    --out results/stop-tune-filament
# reporting range
$D bench --suite held-out $C --unknown source --out results/stop-held-out-wind-known
$D bench --suite held-out-24 --repeats 4 --particles 10000 --strategies dcee-cl \
    --allow-code-change --unknown full --out results/stop-held-out-full
$D bench --suite held-out-24 --repeats 2 --particles 10000 --strategies dcee-cl \
    --allow-code-change --unknown full --truth filament --likelihood fluctuation \
    --set search.lookahead=1 --out results/stop-held-out-filament
