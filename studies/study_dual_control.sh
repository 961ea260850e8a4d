#!/usr/bin/env bash
# The closed-loop DCEE studies (issue 13). Resumable: rerun to finish; each command skips the
# searches already done. Results land in results/ (not versioned); tables are in the README and
# docs/dual-control.md.
# Folders written before 2026-11-22 use the old result layout: convert them with
# `scripts/migrate_results.py DIR` (then resuming needs --allow-code-change, and the campaign
# records both code versions) or give a new --out.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
# the reach R of dcee-cl, chosen on the hard and easy configurations (10,000 particles, 3 repeats)
$D bench --suite hard-easy --repeats 3 --particles 10000 --out results/reach-10k \
    --strategies infotaxis,dcee-cl:reach=3,dcee-cl:reach=4,dcee-cl:reach=6,dcee-cl:reach=8,dcee-cl:reach=10,dcee-cl:reach=12
# the paper's wind-known study at paper scale (20,000 particles, 12 × 10), dcee-cl beside infotaxis
$D bench --suite paper --repeats 10 --strategies dcee-cl,infotaxis --out results/paper-source-cl
# the ablation that explains the paper (10,000 particles, 5 configurations × 5 repeats)
$D bench --suite hard-easy --repeats 5 --particles 10000 --out results/dual-ablation --strategies \
mpc,dcee,dcee:hypotheses=160,dcee:noise=fresh,dcee:noise=fresh:subsample=0.2:hypotheses=25,\
dcee:readings=noise-free,dcee:readings=miss-free,dcee:expectation=stratified,dcee-cl,\
dcee-cl:expectation=sampled,infotaxis,infotaxis:expectation=stratified,entrotaxis,\
entrotaxis:expectation=stratified,dcee:hypotheses=10
# the authors' 75 m domain: does the area explain the paper's MPC and DCEE? (10,000, 5 repeats)
$D bench --suite hard-easy75 --repeats 5 --particles 10000 --out results/dual-ablation-75 \
    --strategies mpc,dcee,dcee-cl,infotaxis
# the full-unknown study at paper scale, dcee-cl beside infotaxis
$D bench --suite paper --repeats 10 --unknown full --strategies dcee-cl,infotaxis --out results/paper-full-cl
# more of the ablation (hypothesis count, reach, entrotaxis, multistage)
$D bench --suite hard-easy --repeats 5 --particles 10000 --out results/dual-ablation --strategies \
dcee-cl:reach=4,dcee-cl:reach=12,dcee-ms,dcee-cl:horizon=2
# the rest of the paper's strategies beside them (same seeds)
$D bench --suite paper --repeats 10 --strategies dcee,mpc --out results/paper-source-cl
$D bench --suite paper --repeats 10 --unknown full --strategies dcee,mpc --out results/paper-full-cl
# the two-move scenario tree against dcee-cl (small: 5,000 particles, 10 + 5 hypotheses, 1 repeat)
$D bench --suite hard-easy --repeats 1 --particles 5000 --out results/dual-tree \
    --strategies dcee-cl:hypotheses=10,dcee-cl-tree:hypotheses=10:branch_hypotheses=5
# the 21-search full-unknown pilot of docs/dual-control.md §6b-6c (paired with paper-full-cl by seed)
for spec in dcee-cl:reach=4 dcee-cl:spread_reach=1 dcee-cl:hypotheses=80 dcee-cl:info_share=0.5 \
    dcee-cl:info_share=1; do
    dir=results/pilot-full/$(echo "$spec" | sed 's/:/+/g; s/=/-/g')
    for K in 1 5 6 7 8 10 12; do for S in 0 1 2; do
        [ -f "$dir/paper-$K-seed$S.json" ] && continue
        $D run --scenario paper:$K --strategy "$spec" --seed $S --particles 20000 --unknown full \
            --out "$dir/paper-$K-seed$S" --json "$dir/paper-$K-seed$S.json" --no-figure -q
    done; done
done
# 2026-11-22: dcee-cl's uncertainty term values every parameter (info_share = 0.5, docs/dual-control.md
# §6c). The 120-search studies again, dcee-cl beside the other planners' searches of the same seeds:
# copies of the folders above (hard links) without their old dcee-cl searches, then the new dcee-cl.
for s in source full; do
    if [ ! -d results/paper-$s-cl2 ]; then
        cp -al results/paper-$s-cl results/paper-$s-cl2
        rm results/paper-$s-cl2/campaign.json && cp results/paper-$s-cl/campaign.json results/paper-$s-cl2/
        rm -rf results/paper-$s-cl2/runs/config=*/strategy=dcee-cl
    fi
done
$D bench --suite paper --repeats 10 --strategies dcee-cl --out results/paper-source-cl2 --allow-code-change
$D bench --suite paper --repeats 10 --unknown full --strategies dcee-cl --out results/paper-full-cl2 \
    --allow-code-change
# the new term in the ablation and in the 75 m area (the old `dcee-cl` rows there are info_share = 0)
$D bench --suite hard-easy --repeats 5 --particles 10000 --out results/dual-ablation --allow-code-change \
    --strategies dcee-cl:info_share=0.5,dcee-cl:info_share=1
$D bench --suite hard-easy75 --repeats 5 --particles 10000 --out results/dual-ablation-75 \
    --allow-code-change --strategies dcee-cl:info_share=0.5
