#!/usr/bin/env bash
# Issue 32: searching a site with obstacles. The `sites` suite (site:wall, site:passage,
# site:nogo; designed for this study, no default chosen on them) for every planner, 10 seeds,
# 10,000 particles, the paper's grid agent; then dcee-cl and infotaxis with the unicycle robot
# (`sites-robot`, 5 seeds). Every summary counts the drives that touched an obstacle or no-go
# zone (`drives_into_obstacles`, checked against the shapes themselves every 5 cm) and the
# shortest way from the start round the obstacles to the source (`start_to_source_travel`).
# Resumable; tables: `dcee report results/sites` and studies/sites_table.py.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
$D bench --suite sites --repeats 10 --particles 10000 --allow-code-change \
    --strategies dcee-cl,infotaxis,entrotaxis,dcee,mpc,dcee-ms --out results/sites
$D bench --suite sites --repeats 5 --particles 10000 --allow-code-change \
    --strategies dcee-mcts --out results/sites-mcts
$D bench --suite sites-robot --repeats 5 --particles 10000 --allow-code-change \
    --strategies dcee-cl,infotaxis --out results/sites-robot
