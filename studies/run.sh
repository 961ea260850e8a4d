#!/usr/bin/env bash
# Reproduce a published table: `bash studies/run.sh NAME` runs the study's campaigns (resumable:
# rerun to finish; finished searches are skipped) and then the step that prints its tables.
# `bash studies/run.sh --list` lists the names; studies/README.md says which table each makes.
set -euo pipefail
cd "$(dirname "$0")/.."
D=.venv/bin/dcee
P=.venv/bin/python
[ -x "$D" ] || bash scripts/setup.sh
report() { for dir in "$@"; do $D report "results/$dir"; cat "results/$dir/report/metrics.md"; done; }
# dcee-cl looked one move ahead everywhere until search.lookahead (2026-11-29, issue 42), two in a
# turbulent plume (grid UAV, one release, open terrain) on 2026-11-29, three since 2026-11-29 (b).
# The turbulent studies flown before pin what they flew, so that each reproduces what it
# published.
# Every campaign stored before 2026-12-02 reported the particles' own 95 % region, before the
# fluctuation likelihood's model-discrepancy floor (estimator.region_floor, issue 42; it changes
# no decision): F0 pins it where such a study is flown again, and the look-ahead pins carry it.
F0=(--set estimator.region_floor=0.0)
LA1=(--set search.lookahead=1 "${F0[@]}")
LA1P=(--pin search.lookahead=1 --pin estimator.region_floor=0.0)  # for precision_variants.py, mixture_region.py
LA2=(--set search.lookahead=2 "${F0[@]}")
# With the count of releases unknown the UAV flew at the paper's fixed 4 m until 2026-12-02 (b),
# when an unset agent.climb became 1 m there too (issue 45): C0 pins the fixed altitude where a
# several-release campaign stored before is flown again (the fluctuation likelihood climbed
# before and after).
C0=(--set agent.climb=0)
# the generations of dcee-cl's lbm rows in docs/results/lbm-held-out-100 (column defaults)
LBM_GENERATIONS=(2026-12-02 2026-11-29b 2026-11-29 2026-11-27c 2026-11-27b 2026-11-27 2026-11-23)
lbm_generation() {  # SUFFIX TAG PAIRS FIGURE [TAG...]: one dcee-cl campaign on the held-out lbm plume stored beside the other generations, paired with the TAG rows of dcee-cl and with every planner at 2026-11-27 (c), its worst searches drawn
  local suffix=$1 tag=$2 pairs=$3 figure=$4 g ref keep=()
  local r=results/turbulent-lbm-held-out-100$suffix lbm=docs/results/lbm-held-out-100
  shift 4
  report "turbulent-lbm-held-out-100$suffix"
  for g in "${LBM_GENERATIONS[@]}"; do [ "$g" = "$tag" ] || keep+=(--keep "defaults:$g"); done
  $P studies/collect_metrics.py --out "$lbm" "${keep[@]}" "$r=defaults:$tag,learn:none,particles:10000"
  rm -f "$lbm/$pairs"
  for g in "$@"; do
    $P studies/pair_campaigns.py "$lbm/searches.csv=strategy:dcee-cl:learn:none:particles:10000.0:defaults:$g" \
      "$r" --csv "$lbm/$pairs" --tag truth_model=lbm
  done
  for ref in dcee-cl infotaxis dcee-mcts; do
    $P studies/pair_campaigns.py "$lbm/searches.csv=strategy:$ref:learn:none:particles:10000.0:defaults:2026-11-27c" \
      "$r" --as "dcee-cl=$ref" --csv "$lbm/$pairs" --tag truth_model=lbm
  done
  $P studies/upwind_detections.py "$r=dcee-cl"
  $P studies/worst_searches.py "$r=dcee-cl" --out "$figure"
}
count_campaigns() {  # PLANNER SUFFIX [SETTINGS...]: its two- and three-release held-out campaigns (issue 45)
  local planner=$1 suffix=$2
  shift 2
  for N in two three; do
    $D bench --suite "$N-source-held-out-100" --repeats 1 --strategies "$planner" "$@" \
      --workers "${WORKERS:-2}" --out "results/$N-source-held-out-100$suffix"
  done
}

# issue 45's held-out table and searches.csv: today's campaigns and, where kept, the same searches
# with the code before the last change (X-before, the paired table), two changes before
# (X-5d04d27), before the hunt for one release more (X-d207b1e) and at 20,000 particles
source_count_tables() {
  # the campaigns this machine holds (a fresh one only those it flew; the CSV keeps the rest)
  $P studies/source_count_table.py $(ls -d results/two-source-held-out-100 \
    results/three-source-held-out-100 results/*-source-held-out-100-before \
    results/*-source-held-out-100-9f200ee results/one-source-*-held-out-100 \
    results/two-source-wind-unknown-held-out-50 results/two-source-filament-held-out-100 \
    results/two-source-puffs-held-out-100 results/two-source-held-out-100-infotaxis \
    results/*-source-held-out-100-mcts results/*-source-held-out-100-climb \
    results/*-source-held-out-100-5d04d27 results/*-source-held-out-100-d207b1e \
    results/three-source-held-out-100-20k 2>/dev/null) \
    --csv docs/results/source-count/searches.csv
}

# The whole dispatch is one brace group, read before any of it runs: bash otherwise reads a
# script as it goes, and an edit to this file during a study (hours) would run the wrong lines.
{
case "${1:---list}" in
  first-look)  # docs/results.md "First look": paper:1-12, seed 0, every planner
    mkdir -p results/first-look
    for K in $(seq 1 12); do for S in dcee mpc entrotaxis infotaxis dcee-ms; do
      out="results/first-look/paper-$K-$S"
      [ -f "$out/summary.json" ] || $D run --scenario "paper:$K" --strategy "$S" --seed 0 --out "$out" --no-figure -q
    done; done
    $D report results/first-look ;;
  paper-source)  # section 5: the paper's planners at today's defaults, wind known, 12 x 10
    $D bench --suite paper --repeats 10 --strategies dcee-cl,infotaxis,dcee,mpc \
      --workers "${WORKERS:-2}" --out results/paper-source
    report paper-source
    $P studies/collect_metrics.py --out docs/results/paper-source results/paper-source
    $P studies/publish_tables.py ;;
  public-wind-known)  # dcee-cl, current defaults, wind known, 12 x 10 (README, docs/turbulent.md)
    $D bench --suite paper --repeats 10 --strategies dcee-cl --out results/public-wind-known
    $D report results/public-wind-known
    cp results/public-wind-known/report/{metrics,per_configuration}.{csv,md} \
      docs/results/public-wind-known-dcee-cl/ ;;
  paper-full)  # section 4.1.1: all eight parameters unknown, today's defaults, 12 x 10
    $D bench --suite paper --repeats 10 --unknown full --strategies dcee-cl,infotaxis,dcee,mpc \
      --workers "${WORKERS:-2}" --out results/paper-full
    report paper-full
    $P studies/collect_metrics.py --out docs/results/paper-full results/paper-full
    $P studies/publish_tables.py ;;
  model-mismatch)  # filament truth, the isotropic estimator
    $D bench --suite paper --strategies dcee,entrotaxis,mpc --repeats 10 --unknown full \
      --truth filament --out results/paper-filament
    report paper-filament ;;
  dual-control)  # closed-loop DCEE: reach, the four planners, the ablation (docs/dual-control.md)
    bash studies/study_dual_control.sh
    $P studies/dual_control_table.py --study results/paper-source-cl
    $P studies/dual_control_table.py results/dual-ablation
    report paper-source-cl2 paper-full-cl paper-full-cl2 ;;
  team)  # several robots, one belief: 2 and 3 robots beside paper-source's one (same seeds)
    # one robot: paper-source's campaign (resumed, or a no-op when it is complete)
    $D bench --suite paper --repeats 10 --strategies dcee-cl,infotaxis,dcee,mpc \
      --workers "${WORKERS:-2}" --out results/paper-source
    for K in 2 3; do
      $D bench --suite paper --repeats 10 --agents "$K" --strategies dcee-cl,infotaxis \
        --workers "${WORKERS:-2}" --out "results/team-a$K"
    done
    $P studies/team_table.py results/paper-source results/team-a2 results/team-a3 \
      --out docs/results/team
    $P studies/publish_tables.py ;;
  turbulent)  # the filament truth with hold-averaged readings and the fluctuation likelihood
    bash studies/study_turbulent.sh
    report filament-fluct ;;
  turbulent-calm)  # the same with the calm model, its ablation and the wind-known price
    bash studies/study_turbulent_calm.sh
    report filament-calm paper-source-calm
    $P studies/bias_table.py results/filament-calm
    $P studies/ablation_table.py results/filament-calm=infotaxis results/filament-info-loc=infotaxis ;;
  turbulent-held-out)  # both turbulent truths on held-out configurations (docs/turbulent.md)
    bash studies/study_turbulent_held_out.sh "${LA1[@]}"
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    # the first three ran at commit 43cea93 (each result records it), before dcee-cl's vertical
    # reach and today's turbulent defaults: their settings are pinned here, and today's code
    # reproduces their infotaxis searches; their dcee-cl searches need that commit
    # before the fourth round: a detection's mean C, no repeat discount
    rr0=(--set estimator.repeat_radius=0.0)
    cm0=(--set estimator.conserve_mean=false "${rr0[@]}")
    bash studies/study_turbulent_held_out.sh "${LA1[@]}" --set agent.climb=0.0 \
      --set estimator.near_source_length=5.0 "${cm0[@]}"
    OUT_SUFFIX=-climb bash studies/study_turbulent_held_out.sh "${LA1[@]}" --set agent.climb=1.0 \
      --set estimator.near_source_length=5.0 "${cm0[@]}"
    OUT_SUFFIX=-climb-nsl25 bash studies/study_turbulent_held_out.sh "${LA1[@]}" --set agent.climb=1.0 \
      --set estimator.near_source_length=2.5 "${cm0[@]}"
    # the third round's defaults (the climbing UAV, near-source length 2.5 m, dcee-cl's
    # vertical reach; a detection's mean C): the puffs on held-out-100, the filament on all 200
    # held-out configurations (issue 28's filament study); the filament's random:1100-1199 make
    # its held-out-100 rows
    # (2.5 m was the near-source fall's default until 2026-11-27: pinned since)
    nsl25=(--set estimator.near_source_length=2.5)
    OUT_SUFFIX=-defaults TRUTHS=puffs bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${cm0[@]}" \
      "${nsl25[@]}"
    SUITE=held-out OUT_SUFFIX=-defaults TRUTHS=filament bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      "${cm0[@]}" "${nsl25[@]}"
    # the fourth round's mean-conserving intermittency alone, the same searches
    OUT_SUFFIX=-cm TRUTHS=puffs bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${rr0[@]}" "${nsl25[@]}"
    SUITE=held-out OUT_SUFFIX=-cm TRUTHS=filament bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      "${rr0[@]}" "${nsl25[@]}"
    # the defaults of 2026-11-23 to 11-27: with the gentle repeat discount (2 m, power 0.25),
    # held-out-100 (today's: turbulent-held-out-today)
    OUT_SUFFIX=-cm-rr bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${nsl25[@]}" \
      --set estimator.repeat_radius=2.0 --set estimator.repeat_power=0.25
    report turbulent-filament-held-out-24 turbulent-puffs-held-out-24
    out=docs/results/turbulent-held-out-100
    gathered=()
    rm -f "$out/climb_vs_fixed.csv" "$out/nsl25_vs_climb.csv" "$out/defaults_vs_nsl25.csv" \
      "$out/cm_vs_defaults.csv" "$out/rr_vs_cm.csv"
    for t in puffs filament; do
      defaults="turbulent-$t-held-out-100-defaults"
      cm="turbulent-$t-held-out-100-cm"
      if [ "$t" = filament ]; then  # all 200
        defaults=turbulent-filament-held-out-defaults
        cm=turbulent-filament-held-out-cm
      fi
      for v in \
        "turbulent-$t-held-out-100=climb:0,near_source_length:5,vertical_reach:0,conserve_mean:0,repeat_radius:0" \
        "turbulent-$t-held-out-100-climb=climb:1,near_source_length:5,vertical_reach:0,conserve_mean:0,repeat_radius:0" \
        "turbulent-$t-held-out-100-climb-nsl25=climb:1,near_source_length:2.5,vertical_reach:0,conserve_mean:0,repeat_radius:0" \
        "$defaults=climb:1,near_source_length:2.5,vertical_reach:1,conserve_mean:0,repeat_radius:0" \
        "$cm=climb:1,near_source_length:2.5,vertical_reach:1,conserve_mean:1,repeat_radius:0" \
        "turbulent-$t-held-out-100-cm-rr=climb:1,near_source_length:2.5,vertical_reach:1,conserve_mean:1,repeat_radius:2"; do
        report "${v%%=*}"
        gathered+=("results/${v%%=*}=truth_model:$t,${v#*=}")
      done
      $P studies/pair_campaigns.py "results/turbulent-$t-held-out-100" \
        "results/turbulent-$t-held-out-100-climb" --csv "$out/climb_vs_fixed.csv" --tag truth_model=$t
      $P studies/pair_campaigns.py "results/turbulent-$t-held-out-100-climb" \
        "results/turbulent-$t-held-out-100-climb-nsl25" --csv "$out/nsl25_vs_climb.csv" \
        --tag truth_model=$t
      $P studies/pair_campaigns.py "results/turbulent-$t-held-out-100-climb-nsl25" \
        "results/$defaults" --csv "$out/defaults_vs_nsl25.csv" --tag truth_model=$t
      $P studies/pair_campaigns.py "results/$defaults" "results/$cm" \
        --csv "$out/cm_vs_defaults.csv" --tag truth_model=$t
      $P studies/pair_campaigns.py "results/$cm" "results/turbulent-$t-held-out-100-cm-rr" \
        --csv "$out/rr_vs_cm.csv" --tag truth_model=$t
    done
    $P studies/calibration_diagnosis.py "results/turbulent-puffs-held-out-100-defaults" \
      results/turbulent-filament-held-out-defaults --csv "$out/calibration-third-round.csv"
    $P studies/calibration_diagnosis.py "results/turbulent-puffs-held-out-100-cm" \
      results/turbulent-filament-held-out-cm --csv "$out/calibration-today.csv"
    $P studies/collect_metrics.py --out "$out" "${gathered[@]}"
    $P studies/publish_tables.py ;;
  turbulent-held-out-today)  # both turbulent truths at the defaults of 2026-11-27 before the backflow member (docs/turbulent.md)
    # the 0.5 m near-source fall and repeat power 1/2, no learned setting (pinned, so a later
    # default keeps these); chosen on these two truths (tuning range random:13-40): a check, not
    # an independent result. Today's defaults: turbulent-held-out-backflow.
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    today=(--set estimator.near_source_length=0.5 --set estimator.repeat_radius=2.0
      --set estimator.repeat_power=0.5 --set 'estimator.learn={}')
    OUT_SUFFIX=-today bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${today[@]}"
    out=docs/results/turbulent-held-out-100-today
    mkdir -p "$out"
    report turbulent-puffs-held-out-100-today turbulent-filament-held-out-100-today
    $P studies/collect_metrics.py --out "$out" --keep defaults:2026-11-27b \
      "results/turbulent-puffs-held-out-100-today=truth_model:puffs,defaults:2026-11-27" \
      "results/turbulent-filament-held-out-100-today=truth_model:filament,defaults:2026-11-27"
    # paired with the defaults of 2026-11-23 where their searches are stored (the filament's,
    # held-out-today; the puffs' old campaign kept only its metrics)
    rm -f "$out/paired.csv"
    for s in dcee-cl infotaxis; do
      $P studies/ablation_table.py "docs/results/held-out-today/searches.csv=$s:study:filament" \
        "results/turbulent-filament-held-out-100-today=$s" --csv "$out/paired.csv" \
        --tag truth_model=filament --tag reference=defaults-2026-11-23
    done
    $P studies/publish_tables.py ;;
  turbulent-held-out-backflow)  # both turbulent truths at today's defaults (the backflow member learned), held-out-100
    # chosen on these two truths (tuning range random:13-40): a check, not an independent
    # result; the rows stored beside those of turbulent-held-out-today (defaults 2026-11-27b)
    # and paired with them search by search from the stored rows
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    OUT_SUFFIX=-today-bf bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set estimator.near_source_length=0.5 --set estimator.repeat_radius=2.0 \
      --set estimator.repeat_power=0.5
    out=docs/results/turbulent-held-out-100-today
    report turbulent-puffs-held-out-100-today-bf turbulent-filament-held-out-100-today-bf
    $P studies/collect_metrics.py --out "$out" --keep defaults:2026-11-27 \
      "results/turbulent-puffs-held-out-100-today-bf=truth_model:puffs,defaults:2026-11-27b" \
      "results/turbulent-filament-held-out-100-today-bf=truth_model:filament,defaults:2026-11-27b"
    rm -f "$out/backflow_vs_before.csv"
    for t in puffs filament; do
      $P studies/pair_campaigns.py "$out/searches.csv=truth_model:$t:defaults:2026-11-27" \
        "results/turbulent-$t-held-out-100-today-bf" --csv "$out/backflow_vs_before.csv" \
        --tag "truth_model=$t"
    done
    $P studies/publish_tables.py ;;
  turbulent-held-out-disc)  # both turbulent truths at today's defaults (the disc member, the mixture's region), held-out-100
    # chosen on these two truths (tuning range random:13-40): a check, not an independent
    # result; stored beside the earlier generations, paired with the backflow member alone
    # (defaults 2026-11-27b) from the stored rows
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    pinned=(--set estimator.near_source_length=0.5 --set estimator.repeat_radius=2.0
      --set estimator.repeat_power=0.5)
    STRATEGIES=dcee-cl OUT_SUFFIX=-today-dm bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${pinned[@]}"
    STRATEGIES=infotaxis OUT_SUFFIX=-today-dm-info bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${pinned[@]}"
    out=docs/results/turbulent-held-out-100-today
    runs=()
    for t in puffs filament; do
      for s in -today-dm -today-dm-info; do
        runs+=("results/turbulent-$t-held-out-100$s=truth_model:$t,defaults:2026-11-27c")
      done
    done
    $P studies/collect_metrics.py --out "$out" --keep defaults:2026-11-27 --keep defaults:2026-11-27b \
      "${runs[@]}"
    rm -f "$out/disc_vs_before.csv"
    for t in puffs filament; do
      for s in -today-dm -today-dm-info; do
        $P studies/pair_campaigns.py "$out/searches.csv=truth_model:$t:defaults:2026-11-27b" \
          "results/turbulent-$t-held-out-100$s" --csv "$out/disc_vs_before.csv" --tag "truth_model=$t"
      done
    done
    $P studies/publish_tables.py ;;
  turbulent-public)  # the twelve public configurations on both turbulent truths: the third round's and today's defaults
    # 5 repeats and 10,000 particles: ~10 min per truth and setting on 2 cores. "defaults": the
    # third round's (a detection's mean C, no repeat discount; flown at commit 69b6ea3, hence
    # --allow-code-change: every version used is recorded); "today": the fourth round's
    for run in "defaults:--set estimator.conserve_mean=false --set estimator.repeat_radius=0.0" \
      "today:"; do
      name=${run%%:*}
      read -r -a pinned <<<"${run#*:}"
      for t in filament puffs; do
        $D bench --suite paper --strategies dcee-cl,infotaxis --repeats 5 --unknown full \
          --likelihood fluctuation --truth $t --particles 10000 --workers "${WORKERS:-2}" \
          --allow-code-change "${pinned[@]}" "${LA1[@]}" --out "results/turbulent-$t-public-$name"
        report "turbulent-$t-public-$name"
      done
      $P studies/collect_metrics.py --out "docs/results/turbulent-public-$name" \
        "results/turbulent-filament-public-$name=truth_model:filament" \
        "results/turbulent-puffs-public-$name=truth_model:puffs"
    done
    $P studies/publish_tables.py ;;
  held-out-today)  # the held-out studies at today's defaults, tree search included (docs/held-out.md)
    # isotropic: all 200 held-out configurations, wind known and full unknown; the one-step
    # planners at today's defaults on the same configurations and seeds (the published
    # held-out-wind-known rows ran without the stall guard: -today is the pair for the tree)
    HO=(--suite held-out --repeats 1 --particles 10000 --allow-code-change --workers "${WORKERS:-2}")
    $D bench "${HO[@]}" --unknown source --strategies dcee-mcts --out results/held-out-wind-known-mcts
    $D bench "${HO[@]}" --unknown full --strategies dcee-mcts --out results/held-out-full-mcts
    $D bench "${HO[@]}" --unknown source --strategies dcee-cl,infotaxis \
      --out results/held-out-wind-known-today
    $D bench "${HO[@]}" --unknown full --strategies dcee-cl,infotaxis --out results/held-out-full
    # the rest of the DCEE family, wind known (theorem-1 DCEE and MPC stall by design)
    $D bench "${HO[@]}" --unknown source --strategies dcee,mpc,dcee-ms \
      --out results/held-out-wind-known-others
    # filament, today's defaults, held-out-100 (random:1100-1199); the one-step planners are
    # turbulent-held-out's -cm-rr campaign (resumed here if missing)
    export SUITE=held-out-100 TRUTHS=filament WORKERS=${WORKERS:-2}
    # (the defaults of 2026-11-23 to 11-27, pinned; today's: turbulent-held-out-today)
    old=(--set estimator.near_source_length=2.5 --set estimator.repeat_radius=2.0
      --set estimator.repeat_power=0.25)
    OUT_SUFFIX=-cm-rr bash studies/study_turbulent_held_out.sh "${LA1[@]}" --allow-code-change "${old[@]}"
    OUT_SUFFIX=-cm-rr-mcts STRATEGIES=dcee-mcts bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --allow-code-change "${old[@]}"
    out=docs/results/held-out-today
    mkdir -p "$out"
    rm -f "$out/paired.csv"
    for pair in wind-known:held-out-wind-known-mcts:held-out-wind-known-today \
      full:held-out-full-mcts:held-out-full \
      filament:turbulent-filament-held-out-100-cm-rr-mcts:turbulent-filament-held-out-100-cm-rr; do
      IFS=: read -r study tree one_step <<<"$pair"
      report "$tree" "$one_step"
      $P studies/ablation_table.py "results/$tree" "results/$one_step=dcee-cl" \
        "results/$one_step=infotaxis" --csv "$out/paired.csv" --tag "study=$study" \
        --tag reference=dcee-mcts
      $P studies/ablation_table.py "results/$one_step=infotaxis" "results/$one_step=dcee-cl" \
        --csv "$out/paired.csv" --tag "study=$study" --tag reference=infotaxis
    done
    report held-out-wind-known-others
    $P studies/ablation_table.py results/held-out-wind-known-today=infotaxis \
      results/held-out-wind-known-others=dcee results/held-out-wind-known-others=mpc \
      results/held-out-wind-known-others=dcee-ms --csv "$out/paired.csv" --tag study=wind-known \
      --tag reference=infotaxis
    $P studies/collect_metrics.py --out "$out" \
      results/held-out-wind-known-mcts=study:wind-known \
      results/held-out-wind-known-today=study:wind-known \
      results/held-out-wind-known-others=study:wind-known \
      results/held-out-full-mcts=study:full results/held-out-full=study:full \
      results/turbulent-filament-held-out-100-cm-rr-mcts=study:filament \
      results/turbulent-filament-held-out-100-cm-rr=study:filament
    $P studies/worst_searches.py results/held-out-wind-known-mcts=dcee-mcts \
      results/held-out-full-mcts=dcee-mcts \
      results/turbulent-filament-held-out-100-cm-rr-mcts=dcee-mcts \
      --out docs/figures/held-out-worst-mcts.png
    $P studies/worst_searches.py results/held-out-wind-known-today=dcee-cl \
      results/held-out-wind-known-today=infotaxis results/held-out-full=dcee-cl \
      results/held-out-full=infotaxis --out docs/figures/held-out-worst-today.png
    # why the tree ends further away: more hypothesised readings per sequence (tuning range)
    $D bench --suite random-tune-12 --repeats 1 --particles 10000 --unknown full \
      --strategies 'dcee-cl,dcee-mcts,dcee-mcts:n_hypotheses=40' --workers "${WORKERS:-2}" \
      --out results/tune-mcts-hypotheses
    $P studies/ablation_table.py results/tune-mcts-hypotheses=dcee-mcts \
      results/tune-mcts-hypotheses=dcee-mcts:n_hypotheses=40 results/tune-mcts-hypotheses=dcee-cl
    $P studies/publish_tables.py ;;
  held-out)  # random configurations of the reporting range (docs/held-out.md)
    bash studies/study_held_out.sh
    report held-out-wind-known held-out-full held-out-filament ;;
  replay)  # filters that keep every mode, against the exact grid posterior
    $P studies/replay_study.py ;;
  spike)  # one absurd reading inside a search (outlier safety)
    $P studies/spike_study.py ;;
  fuzz)  # random reading streams: no dead filter
    $P studies/fuzz_filter.py ;;
  lab)  # the paper's indoor experiment in simulation (section 6)
    WORKERS=${WORKERS:-2} bash studies/study_lab.sh
    $P studies/lab_table.py results/lab-robot=robot-isotropic results/lab-grid=grid-isotropic \
      results/lab-robot-filament-fit=robot-filament-room \
      results/lab-robot-filament=robot-filament-50m --out docs/results/lab
    $P studies/publish_tables.py ;;
  precision)  # where a turbulent search's final error comes from (docs/turbulent.md)
    # the table's rows, with the defaults of the session that measured it written out
    # (near_source_length 10 m, reading_weight 1), so it reproduces with today's defaults
    old=estimator.near_source_length=10,estimator.reading_weight=1.0
    mkdir -p docs/results
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:1-12 --truths puffs filament \
      --variant "defaults:$old" --variant "hold8:$old,agent.dwell=8" \
      --variant "logsd2:$old,estimator.log_sd=2.0" \
      --variant "intermittency0.8:$old,estimator.intermittency=0.8" \
      --variant "n20k:$old,search.particles=20000" \
      --variant "nsl5:estimator.near_source_length=5,estimator.reading_weight=1.0" \
      --variant "nsl7:estimator.near_source_length=7,estimator.reading_weight=1.0" \
      --variant "rw0.5:estimator.near_source_length=10,estimator.reading_weight=0.5" \
      --variant "nsl5rw0.5:estimator.near_source_length=5,estimator.reading_weight=0.5" \
      --csv docs/results/precision-tune.csv ;;
  turbulent-tune)  # the second and third tuning rounds, random:13-40 (docs/turbulent.md)
    out=docs/results/tuning-turbulent-13-40
    tune() {  # CSV, then --variant/--strategy arguments
      local csv=$1; shift
      $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths filament puffs "$@" \
        --csv "$out/$csv"
    }
    # second round, with the defaults of its day: a fixed altitude unless climbing, the
    # near-source length 5 m, dcee-cl without the vertical reach
    cm0=estimator.conserve_mean=false,estimator.repeat_radius=0.0  # before the fourth round
    old=estimator.near_source_length=5.0,$cm0
    tune guard-share.csv --variant "base:agent.climb=0.0,$old,search.guard_share=1.0" \
      --variant "g015:agent.climb=0.0,$old,search.guard_share=0.15" \
      --strategy dcee-cl:vertical_reach=0
    tune climb.csv --variant "climb1:agent.climb=1.0,$old" --strategy dcee-cl:vertical_reach=0
    tune climb-nsl25.csv \
      --variant c1n25:agent.climb=1.0,estimator.near_source_length=2.5,$cm0 \
      --strategy dcee-cl:vertical_reach=0
    # third round: dcee-cl's vertical reach (today's default 1), then the reading weight and the
    # near-source length with it, and the near-source length 2.5 m at a fixed altitude
    # (the detection's mean C, as before the fourth round's mean-conserving intermittency)
    c1=estimator.conserve_mean=false,estimator.repeat_radius=0.0,agent.climb=1.0
    c1=$c1,estimator.near_source_length
    tune climb-nsl25-vr1.csv --variant "c1n25vr1:$c1=2.5"
    tune climb-nsl25-vr1-w03.csv --variant "c1n25vr1w03:$c1=2.5,estimator.reading_weight=0.3"
    tune climb-nsl25-vr1-w04.csv --variant "c1n25vr1w04:$c1=2.5,estimator.reading_weight=0.4"
    tune climb-nsl35-vr1.csv --variant "c1n35vr1:$c1=3.5"
    tune fixed-nsl25.csv \
      --variant n25:estimator.conserve_mean=false,estimator.repeat_radius=0.0,agent.climb=0.0,estimator.near_source_length=2.5
    # the repeat discount at the third round's defaults (both rows were stopped early: see the
    # README)
    p1=estimator.repeat_power=1.0
    tune repeat-radius-2-partial.csv --variant "rr2:$cm0,estimator.repeat_radius=2.0,$p1"
    tune repeat-radius-05-partial.csv --variant "rr05:$cm0,estimator.repeat_radius=0.5,$p1"
    # fourth round: the mean-conserving intermittency, alone and with the reading weight 0.4
    # (the repeat discount off unless a variant sets it, as before the fourth round's default)
    tune conserve-mean.csv --variant cm:estimator.conserve_mean=true,estimator.repeat_radius=0.0
    tune conserve-mean-w04-partial.csv --variant \
      cm-w04:estimator.conserve_mean=true,estimator.reading_weight=0.4,estimator.repeat_radius=0.0
    # (stopped at 37 and 54 of 56: see the README)
    tune repeat-2-power-05-partial.csv \
      --variant rr2p05:estimator.repeat_radius=2.0,estimator.repeat_power=0.5
    tune repeat-2-power-025.csv \
      --variant rr2p025:estimator.repeat_radius=2.0,estimator.repeat_power=0.25
    for unk in source full; do
      $D bench --suite random-tune --strategies dcee-cl --repeats 1 --unknown $unk \
        --particles 10000 --set search.guard_share=1.0 --out "results/tune-guard-$unk-1"
      $D bench --suite random-tune --strategies dcee-cl --repeats 1 --unknown $unk \
        --particles 10000 --set search.guard_share=0.15 --out "results/tune-guard-$unk-015"
    done
    $P studies/ablation_table.py results/tune-guard-source-1 results/tune-guard-source-015
    $P studies/ablation_table.py results/tune-guard-full-1 results/tune-guard-full-015
    for unk in source full; do  # the climb on the isotropic truth, each planner against itself
      $D bench --suite random-tune --strategies dcee-cl,infotaxis --repeats 1 --unknown $unk \
        --particles 10000 --set agent.climb=1.0 --out "results/tune-climb-$unk"
      $D bench --suite random-tune --strategies infotaxis --repeats 1 --unknown $unk \
        --particles 10000 --out "results/tune-info-$unk"
      $P studies/ablation_table.py "results/tune-guard-$unk-015=dcee-cl" \
        "results/tune-climb-$unk=dcee-cl"
      $P studies/ablation_table.py "results/tune-info-$unk=infotaxis" \
        "results/tune-climb-$unk=infotaxis"
    done ;;
  stop-rule)  # the stop-when-localised rule: tuning and held-out replays (docs/results.md §7)
    bash studies/study_stop_rule.sh
    $P studies/stop_rule_table.py results/stop-tune-wind-known results/stop-tune-full \
      results/stop-tune-filament --grid
    mkdir -p docs/results/stop-rule
    $P studies/stop_rule_table.py results/stop-held-out-wind-known results/stop-held-out-full \
      results/stop-held-out-filament --csv docs/results/stop-rule/stop_rule.csv
    $P studies/publish_tables.py ;;
  sites)  # every planner around obstacles (wall, passage, no-go zone), grid and unicycle
    bash studies/study_sites.sh
    mkdir -p docs/results/sites
    $P studies/sites_table.py results/sites results/sites-mcts results/sites-robot \
      --csv docs/results/sites/sites.csv
    $P studies/publish_tables.py ;;
  sites-walls-lookahead)  # issue 44: dcee-cl at its site look-ahead (unset: SITE_LOOKAHEAD) against one move ahead and the wall-blind estimator, the four held-out sites, 10 seeds, one code version
    B="$D bench --suite sites-walls --strategies dcee-cl --repeats 10 --particles 10000 --workers ${WORKERS:-2}"
    W="--set estimator.plume=walls"
    $B $W --out results/sites-walls-aware-lookahead
    $B $W --set search.lookahead=1 --out results/sites-walls-aware-one-move
    $B "${F0[@]}" --out results/sites-walls-blind-today  # the wall-blind estimator at its defaults (one move ahead)
    $P studies/sites_walls_table.py "wall-aware, three moves ahead (default)=results/sites-walls-aware-lookahead" \
      "wall-aware, one move ahead=results/sites-walls-aware-one-move" \
      "wall-blind=results/sites-walls-blind-today" --out docs/results/sites-walls-lookahead
    $P studies/publish_tables.py ;;
  sites-tune-lookahead)  # issue 44: dcee-cl one, two and three moves ahead on the tuning sites random-site:1-20, wall-aware estimator (never reported as a result)
    B="$D bench --suite sites-tune --strategies dcee-cl --repeats 1 --particles 10000 --workers ${WORKERS:-2} --set estimator.plume=walls"
    for L in 1 2 3; do
      $B --set search.lookahead=$L --out results/sites-tune-la$L
    done
    $P studies/sites_walls_table.py "one move ahead=results/sites-tune-la1" \
      "two moves ahead=results/sites-tune-la2" "three moves ahead=results/sites-tune-la3" \
      --out docs/results/sites-walls-tune/lookahead ;;
  sites-walls-tune)  # issue 44: the wall-aware estimator's variants on the tuning sites random-site:1-20 (never reported as a result)
    # every round flew dcee-cl one move ahead (the site default before 2026-11-29 (e)): pinned
    B="$D bench --suite sites-tune --strategies dcee-cl --repeats 1 --particles 10000 --workers ${WORKERS:-2} ${LA1[*]}"
    # round 5: the diffusivity bank with a fourth member (1, 3, 10 × ζ1 is the default; ζ1 = 1 here)
    $B --set estimator.plume=walls --set 'estimator.learn={wall_diffusivity=[1.0,3.0,10.0,30.0]}' \
      --out results/sites-tune-k30
    # round 4: the reading weight with the wall-aware estimator (0.5 is the default: round 3's nu1)
    $B --set estimator.plume=walls --set estimator.reading_weight=0.25 --out results/sites-tune-rw0.25
    # round 3: the wake wind's eddy viscosity ν_t (1 m²/s is the default)
    for NU in 1 0.5 0.25; do
      $B --set estimator.plume=walls --set estimator.wall_viscosity=$NU --out results/sites-tune-nu$NU
    done
    $P studies/sites_walls_table.py "nu 1 (default)=results/sites-tune-nu1" \
      "nu 0.5=results/sites-tune-nu0.5" "nu 0.25=results/sites-tune-nu0.25" \
      --out docs/results/sites-walls-tune/viscosity
    $P studies/sites_walls_table.py "reading weight 0.5 (default)=results/sites-tune-nu1" \
      "reading weight 0.25=results/sites-tune-rw0.25" --out docs/results/sites-walls-tune/reading-weight
    $P studies/sites_walls_table.py "K bank 1,3,10 (default)=results/sites-tune-nu1" \
      "K bank 1,3,10,30=results/sites-tune-k30" --out docs/results/sites-walls-tune/diffusivity-bank
    $P studies/site_flow_fidelity.py --sites 1-8 --viscosities 0.25,0.5,1,2,4 \
      --out docs/results/sites-walls-tune/viscosity/fidelity.csv
    # round 2: the wind round the buildings (wake: constant-eddy-viscosity Navier-Stokes; potential: mass-consistent)
    $B --set estimator.plume=walls --set estimator.wall_wind=wake --out results/sites-tune-wake
    $B --set estimator.plume=walls --set estimator.wall_wind=potential --out results/sites-tune-potential
    # round 1 (the mass-consistent wind): decay and K
    W="--set estimator.plume=walls --set estimator.wall_wind=potential"
    $B $W --set truth.zeta2=1000 --out results/sites-tune-C
    $B $W --out results/sites-tune-B
    $B $W --set 'estimator.learn={}' --out results/sites-tune-A
    $B --out results/sites-tune-blind
    $P studies/sites_walls_table.py "wake wind (chosen)=results/sites-tune-wake" \
      "potential wind=results/sites-tune-potential" \
      "potential, no decay, K learned (C)=results/sites-tune-C" \
      "potential, decay 8 s, K learned (B)=results/sites-tune-B" \
      "potential, decay 8 s, K fixed (A)=results/sites-tune-A" \
      "wall-blind=results/sites-tune-blind" --out docs/results/sites-walls-tune
    $P studies/publish_tables.py ;;
  sites-walls)  # issue 44: gas round buildings, the lbm truth on the four sites with walls, wall-aware (wake and potential wind) against wall-blind, dcee-cl and infotaxis, 10 seeds
    B="$D bench --suite sites-walls --repeats 10 --particles 10000 --workers ${WORKERS:-2}"
    W="--set estimator.plume=walls"
    P2="--set estimator.wall_wind=potential"
    for s in dcee-cl infotaxis; do
      x=$([ $s = infotaxis ] && echo -infotaxis || true)
      # dcee-cl flew one move ahead here (the site default before 2026-11-29 (e)): pinned;
      # infotaxis does not read search.lookahead
      pin=$([ $s = dcee-cl ] && echo "${LA1[*]}" || true)
      $B --strategies $s $W $pin --out results/sites-walls-aware$x
      $B --strategies $s $W $P2 $pin --out results/sites-walls-aware-potential$x
      $B --strategies $s "${F0[@]}" --out results/sites-walls-blind$x
    done
    $P studies/sites_walls_table.py wall-aware=results/sites-walls-aware \
      "wall-aware, potential wind=results/sites-walls-aware-potential" \
      wall-blind=results/sites-walls-blind wall-aware=results/sites-walls-aware-infotaxis \
      "wall-aware, potential wind=results/sites-walls-aware-potential-infotaxis" \
      wall-blind=results/sites-walls-blind-infotaxis --out docs/results/sites-walls
    $P studies/publish_tables.py ;;
  sites-walls-planners)  # issue 44: the other planners on the four sites with walls, wall-aware against wall-blind, 10 seeds
    B="$D bench --suite sites-walls --repeats 10 --particles 10000 --workers ${WORKERS:-2} --strategies dcee,dcee-ms,mpc,entrotaxis,dcee-mcts"
    $B --set estimator.plume=walls --out results/sites-walls-aware-planners
    $B "${F0[@]}" --out results/sites-walls-blind-planners
    $P studies/sites_walls_table.py wall-aware=results/sites-walls-aware-planners \
      wall-blind=results/sites-walls-blind-planners --out docs/results/sites-walls-planners
    $P studies/publish_tables.py ;;
  sites-walls-timing)  # issue 44: decision time on a site against open terrain (idle machine, one pinned core)
    $P studies/site_timing.py --out docs/results/sites-walls/timing.csv ;;
  anemometer)  # the full-unknown study with and without a measured wind (paired)
    bash studies/study_anemometer.sh
    mkdir -p docs/results/anemometer
    $P studies/anemometer_table.py results/anemometer-off results/anemometer-on \
      --vague results/anemometer-off-vague results/anemometer-on-vague \
      --csv docs/results/anemometer/anemometer.csv
    $P studies/publish_tables.py ;;
  tune-horizon)  # issue 42: dcee-cl looking two moves ahead on the tuning range, filament + puffs (docs/results/tuning-horizon-13-40)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant horizon2: --strategy dcee-cl:horizon=2 --workers "${WORKERS:-2}" \
      --csv docs/results/tuning-horizon-13-40/variants.csv ;;
  tune-region-floor)  # issue 42: the 95 % region's model-discrepancy floor on the tuning range, filament + puffs, rule written first (docs/results/tuning-region-floor-13-40)
    out=docs/results/tuning-region-floor-13-40
    $P studies/precision_variants.py --configs random:13-40 --truths puffs filament \
      --variant today: --strategy dcee-cl --workers "${WORKERS:-2}" --csv "$out/variants.csv"
    $P studies/region_floor.py "$out/variants.csv" --csv "$out/coverage.csv" --choose 0.95
    $P studies/publish_tables.py ;;
  tune-lookahead3)  # issue 42: dcee-cl looking three moves ahead on the tuning range, filament + puffs (docs/results/tuning-lookahead3-13-40)
    $P studies/precision_variants.py --configs random:13-40 --truths puffs filament \
      --variant lookahead3:search.lookahead=3 --pin estimator.region_floor=0.0 --strategy dcee-cl \
      --workers "${WORKERS:-2}" \
      --csv docs/results/tuning-lookahead3-13-40/variants.csv
    $P studies/publish_tables.py ;;
  lbm-endgame)  # issue 42, a lab note: where each planner reads last and ends on the lbm plume, eight tuning configurations (docs/plumes.md)
    for s in dcee-cl dcee-cl:horizon=2 dcee-mcts dcee-mcts:depth=1 infotaxis; do
      for k in 13 14 15 16 17 18 19 20; do
        [ -f "results/lbm-endgame/$s-$k/summary.json" ] || $D run --scenario random:$k --unknown full \
          --likelihood fluctuation --truth lbm --particles 10000 --set truth.z=4.0 --strategy "$s" \
          "${LA1[@]}" --seed 0 --out "results/lbm-endgame/$s-$k" -q --no-figure
      done
    done
    $P studies/lbm_endgame.py results/lbm-endgame/*-[0-9]* --csv docs/results/lbm-plume/endgame.csv
    $P studies/publish_tables.py ;;
  lbm-plume)  # the fluid solver's plume against published plume measurements (docs/scenarios.md)
    $P studies/lbm_statistics.py
    $P studies/publish_tables.py ;;
  tune-learn)  # the learned reading model (estimator.learn) on the tuning range, filament + puffs (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant base: \
      --variant 'decay:estimator.learn={decay=[1.0,0.5]}' \
      --variant 'nsl:estimator.learn={near_source_length=[2.5,0.0]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-learn-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-log-sd)  # the learned log-normal spread on the tuning range, filament + puffs (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant base: \
      --variant 'sd:estimator.learn={log_sd=[1.3,2.0,3.0]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-log-sd-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-near-sd)  # the learned near-source spread on the tuning range, filament + puffs (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'nearsd:estimator.log_sd_length=1.5,estimator.learn={log_sd_near=[0.0,3.0,6.0]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-near-sd-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-nsl05)  # a 0.5 m near-source fall on the tuning range, filament + puffs (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'nsl05:estimator.near_source_length=0.5' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-nsl05-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-nsl05-rp05)  # the 0.5 m fall with a repeat discount of power 1/2, tuning range (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'nsl05rp05:estimator.near_source_length=0.5,estimator.repeat_power=0.5' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-nsl05-rp05-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-backflow)  # gas upwind of the release, learned, on the tuning range (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant base: --variant 'backflow:estimator.learn={backflow=[0.0,0.05]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-backflow-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-source-radius)  # a release spread over a disc, learned, on the tuning range (docs/plumes.md)
    # paired with today's defaults: the backflow rows of docs/results/tuning-backflow-13-40
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'radius:estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-source-radius-13-40/variants.csv
    $P studies/publish_tables.py ;;
  tune-area-release)  # the tuning truths released over an area: do they reproduce the lbm failure? (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'area:truth.model.puff_radius=0.5' \
      --variant 'area-radius:truth.model.puff_radius=0.5,estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-area-release-13-40/variants.csv ;;
  tune-area-release-1m)  # the tuning truths released over a 1 m disc at today's defaults: a closer stand-in for the lbm plume? (docs/plumes.md)
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant 'area1:truth.model.puff_radius=1.0' \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-area-release-1m-13-40/variants.csv ;;
  tune-radius-prior)  # disc members with prior odds 9:1 against, on point and area releases (docs/plumes.md)
    cand='estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]},estimator.learn_prior={source_radius=[0.9,0.1]}'
    $P studies/precision_variants.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant "prior:$cand" --variant "area-prior:truth.model.puff_radius=0.5,$cand" \
      --workers "${WORKERS:-2}" --csv docs/results/tuning-radius-prior-13-40/variants.csv ;;
  mixture-region)  # the 95 % region of the reading models' mixture beside the selected one's, disc members (docs/plumes.md)
    cand='estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}'
    $P studies/mixture_region.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant "radius:$cand" --variant "area-radius:truth.model.puff_radius=0.5,$cand" \
      --workers "${WORKERS:-2}" --csv docs/results/mixture-region-13-40/searches.csv ;;
  mixture-region-prior)  # disc members with prior odds 9:1 against and the mixture's region, point and area releases (docs/plumes.md)
    cand='estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]},estimator.learn_prior={source_radius=[0.9,0.1]}'
    $P studies/mixture_region.py "${LA1P[@]}" --configs random:13-40 --truths puffs filament \
      --variant "prior:$cand" --variant "area-prior:truth.model.puff_radius=0.5,$cand" \
      --workers "${WORKERS:-2}" --csv docs/results/mixture-region-prior-13-40/searches.csv ;;
  region-floor-held-out)  # issue 42: dcee-cl at today's defaults (the region's model-discrepancy floor since 2026-12-02) on the held-out lbm plume, stored beside the earlier generations
    # nothing is decided on the lbm plume; the floor changes what is reported and no decision,
    # so the pairs with 2026-11-29 (b) (the same planner) show what the floor does to the region
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    TRUTHS=lbm STRATEGIES=dcee-cl OUT_SUFFIX=-d1202 bash studies/study_turbulent_held_out.sh \
      --set truth.z=4.0
    lbm_generation -d1202 2026-12-02 floor_vs_before.csv \
      docs/figures/lbm-held-out-worst-floor.png 2026-11-29b
    $P studies/region_floor.py results/turbulent-lbm-held-out-100-d1202 \
      --csv docs/results/lbm-held-out-100/region_floor.csv
    $P studies/publish_tables.py ;;
  region-floor-held-out-infotaxis)  # issue 42: infotaxis at today's defaults (the region's floor) on the held-out lbm plume, beside dcee-cl's generation of 2026-12-02
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    TRUTHS=lbm STRATEGIES=infotaxis OUT_SUFFIX=-d1202-info bash studies/study_turbulent_held_out.sh \
      --set truth.z=4.0
    r=results/turbulent-lbm-held-out-100-d1202-info lbm=docs/results/lbm-held-out-100
    report turbulent-lbm-held-out-100-d1202-info
    keep=()
    for g in "${LBM_GENERATIONS[@]}"; do keep+=(--keep "defaults:$g"); done
    $P studies/collect_metrics.py --out "$lbm" "${keep[@]}" \
      "$r=defaults:2026-12-02,learn:none,particles:10000"
    rm -f "$lbm/floor_infotaxis_vs_before.csv"
    $P studies/pair_campaigns.py \
      "$lbm/searches.csv=strategy:infotaxis:learn:none:particles:10000.0:defaults:2026-11-27c" "$r" \
      --csv "$lbm/floor_infotaxis_vs_before.csv" --tag truth_model=lbm
    $P studies/region_floor.py "$r" --csv "$lbm/region_floor_infotaxis.csv"
    $P studies/publish_tables.py ;;
  lookahead3-held-out)  # issue 42: dcee-cl at today's defaults (three moves ahead since 2026-11-29 (b)) on the held-out lbm plume, stored beside the earlier generations
    # the lbm plume held out (no default chosen on it); paired with the two-move rows of
    # 2026-11-29 and the other planners' rows of 2026-11-27 (c) (unchanged: today's)
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    TRUTHS=lbm STRATEGIES=dcee-cl OUT_SUFFIX=-d29b bash studies/study_turbulent_held_out.sh \
      --set truth.z=4.0 "${F0[@]}"
    lbm_generation -d29b 2026-11-29b lookahead3_vs_before.csv \
      docs/figures/lbm-held-out-worst-lookahead3.png 2026-11-29
    $P studies/publish_tables.py ;;
  lookahead-held-out)  # issue 42: dcee-cl at the defaults of 2026-11-29 (two moves ahead, search.lookahead) on the held-out lbm plume and both turbulent truths, stored beside the earlier generations
    # the lbm plume held out (no default chosen on it); filament and puffs, where the look-ahead
    # was chosen (a check, not an independent result). The other planners did not change: their
    # rows of 2026-11-27 (c) are today's. Rows of earlier generations kept from the stored study
    # (their search folders need not be on this machine), each new search paired with them.
    export SUITE=held-out-100 WORKERS=${WORKERS:-2}
    TRUTHS=lbm STRATEGIES=dcee-cl OUT_SUFFIX=-d29 bash studies/study_turbulent_held_out.sh \
      "${LA2[@]}" --set truth.z=4.0
    STRATEGIES=dcee-cl OUT_SUFFIX=-today-d29 bash studies/study_turbulent_held_out.sh "${LA2[@]}"
    lbm_generation -d29 2026-11-29 lookahead_vs_before.csv \
      docs/figures/lbm-held-out-worst-lookahead.png
    out=docs/results/turbulent-held-out-100-today
    runs=()
    for t in puffs filament; do
      [ -d "results/turbulent-$t-held-out-100-today-d29" ] || continue
      report "turbulent-$t-held-out-100-today-d29"
      runs+=("results/turbulent-$t-held-out-100-today-d29=truth_model:$t,defaults:2026-11-29")
    done
    $P studies/collect_metrics.py --out "$out" --keep defaults:2026-11-27 \
      --keep defaults:2026-11-27b --keep defaults:2026-11-27c "${runs[@]}"
    rm -f "$out/lookahead_vs_before.csv"
    for t in puffs filament; do
      [ -d "results/turbulent-$t-held-out-100-today-d29" ] || continue
      $P studies/pair_campaigns.py "$out/searches.csv=truth_model:$t:defaults:2026-11-27c" \
        "results/turbulent-$t-held-out-100-today-d29" --csv "$out/lookahead_vs_before.csv" \
        --tag "truth_model=$t"
    done
    $P studies/publish_tables.py ;;
  cross-truth)  # every truth at today's defaults; the lbm plume held out (docs/plumes.md, README)
    # dcee-cl, infotaxis and the tree search at today's defaults, 100 held-out configurations
    export SUITE=held-out-100 TRUTHS=lbm WORKERS=${WORKERS:-2}
    # today's defaults (since 2026-12-02: the region's floor; dcee-cl three moves ahead since
    # 2026-11-29 (b); the other planners as below, flown before the floor: pinned), those of
    # 2026-11-29 (b) (three moves, no floor) and of 2026-11-29 (dcee-cl two moves ahead, pinned)
    STRATEGIES=dcee-cl OUT_SUFFIX=-d1202 bash studies/study_turbulent_held_out.sh --set truth.z=4.0
    STRATEGIES=dcee-cl OUT_SUFFIX=-d29b bash studies/study_turbulent_held_out.sh --set truth.z=4.0 \
      "${F0[@]}"
    STRATEGIES=dcee-cl OUT_SUFFIX=-d29 bash studies/study_turbulent_held_out.sh "${LA2[@]}" \
      --set truth.z=4.0
    # the defaults of 2026-11-27 (c): the disc member at prior odds 9:1, the mixture's
    # region; the same searches as -radius-prior below, the region now the mixture's
    STRATEGIES=dcee-cl OUT_SUFFIX=-dm bash studies/study_turbulent_held_out.sh "${LA1[@]}" --set truth.z=4.0
    STRATEGIES=infotaxis OUT_SUFFIX=-dm-info bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set truth.z=4.0
    STRATEGIES=dcee-mcts OUT_SUFFIX=-mcts-dm bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set truth.z=4.0
    # an option measured at today's defaults (it decides nothing): dcee-cl looking two moves
    # ahead (chosen as a candidate on the tuning range: bash studies/run.sh tune-horizon)
    STRATEGIES=dcee-cl:horizon=2 OUT_SUFFIX=-dm-h2 bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set truth.z=4.0
    # the defaults of 2026-11-27 (b): the backflow member learned, alone (pinned)
    bf=(--set truth.z=4.0 --set 'estimator.learn={backflow=[0.0,0.05]}')
    OUT_SUFFIX=-bf bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${bf[@]}"
    STRATEGIES=dcee-mcts OUT_SUFFIX=-mcts-bf bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${bf[@]}"
    # an option measured at today's defaults (it decides nothing): a release spread over a disc
    STRATEGIES=dcee-cl OUT_SUFFIX=-radius bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set truth.z=4.0 --set 'estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}'
    # the same with prior odds 9:1 against the disc (tune-radius-prior decides whether it is a default)
    STRATEGIES=dcee-cl OUT_SUFFIX=-radius-prior bash studies/study_turbulent_held_out.sh "${LA1[@]}" \
      --set truth.z=4.0 --set 'estimator.learn={backflow=[0.0,0.05],source_radius=[0.0,1.0]}' \
      --set 'estimator.learn_prior={source_radius=[0.9,0.1]}'
    # the defaults of 2026-11-27 before the backflow member (pinned: no learned setting)
    nobf=(--set truth.z=4.0 --set 'estimator.learn={}')
    bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${nobf[@]}"
    STRATEGIES=dcee-mcts OUT_SUFFIX=-mcts-today bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${nobf[@]}"
    # the same at the defaults of 2026-11-23 to 11-27 (a 2.5 m near-source fall, repeat power 1/4),
    # and options measured at those defaults (they decide nothing): dcee-cl with the learned
    # decay and the learned near-source intermittency, the tree search, 20,000 particles
    old=(--set truth.z=4.0 --set estimator.near_source_length=2.5 --set estimator.repeat_power=0.25
      --set 'estimator.learn={}')
    OUT_SUFFIX=-nsl25 bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${old[@]}"
    STRATEGIES=dcee-cl OUT_SUFFIX=-decay bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${old[@]}" \
      --set 'estimator.learn={decay=[1.0,0.5]}'
    STRATEGIES=dcee-mcts OUT_SUFFIX=-mcts bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${old[@]}"
    STRATEGIES=dcee-cl OUT_SUFFIX=-nsl bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${old[@]}" \
      --set 'estimator.learn={near_source_length=[2.5,0.0]}'
    STRATEGIES=dcee-cl OUT_SUFFIX=-20k bash studies/study_turbulent_held_out.sh "${LA1[@]}" "${old[@]}" \
      --particles 20000
    r=results/turbulent-lbm-held-out-100
    report turbulent-lbm-held-out-100-d1202 turbulent-lbm-held-out-100-d29b turbulent-lbm-held-out-100-d29 \
      turbulent-lbm-held-out-100-dm turbulent-lbm-held-out-100-dm-info turbulent-lbm-held-out-100-mcts-dm \
      turbulent-lbm-held-out-100-dm-h2 \
      turbulent-lbm-held-out-100-bf turbulent-lbm-held-out-100-mcts-bf turbulent-lbm-held-out-100-radius \
      turbulent-lbm-held-out-100-radius-prior \
      turbulent-lbm-held-out-100 turbulent-lbm-held-out-100-mcts-today \
      turbulent-lbm-held-out-100-nsl25 turbulent-lbm-held-out-100-decay \
      turbulent-lbm-held-out-100-mcts turbulent-lbm-held-out-100-nsl turbulent-lbm-held-out-100-20k
    $P studies/collect_metrics.py --out docs/results/lbm-held-out-100 \
      "$r-d1202=defaults:2026-12-02,learn:none,particles:10000" \
      "$r-d29b=defaults:2026-11-29b,learn:none,particles:10000" \
      "$r-d29=defaults:2026-11-29,learn:none,particles:10000" \
      "$r-dm=defaults:2026-11-27c,learn:none,particles:10000" \
      "$r-dm-info=defaults:2026-11-27c,learn:none,particles:10000" \
      "$r-mcts-dm=defaults:2026-11-27c,learn:none,particles:10000" \
      "$r-dm-h2=defaults:2026-11-27c,learn:none,particles:10000" \
      "$r-bf=defaults:2026-11-27b,learn:none,particles:10000" \
      "$r-mcts-bf=defaults:2026-11-27b,learn:none,particles:10000" \
      "$r-radius=defaults:2026-11-27b,learn:backflow+source_radius,particles:10000" \
      "$r-radius-prior=defaults:2026-11-27b,learn:backflow+source_radius with prior odds 9:1 against the disc,particles:10000" \
      "$r=defaults:2026-11-27,learn:none,particles:10000" \
      "$r-mcts-today=defaults:2026-11-27,learn:none,particles:10000" \
      "$r-nsl25=defaults:2026-11-23,learn:none,particles:10000" \
      "$r-decay=defaults:2026-11-23,learn:decay,particles:10000" \
      "$r-mcts=defaults:2026-11-23,learn:none,particles:10000" \
      "$r-nsl=defaults:2026-11-23,learn:near_source_length,particles:10000" \
      "$r-20k=defaults:2026-11-23,learn:none,particles:20000"
    rm -f docs/results/lbm-held-out-100/paired.csv docs/results/lbm-held-out-100/today_vs_before.csv \
      docs/results/lbm-held-out-100/backflow_vs_before.csv
    for ref in infotaxis dcee-cl; do
      $P studies/ablation_table.py "$r-nsl25=$ref" "$r-nsl25=dcee-cl" "$r-decay=dcee-cl" \
        "$r-mcts=dcee-mcts" "$r-nsl=dcee-cl" "$r-20k=dcee-cl" \
        --csv docs/results/lbm-held-out-100/paired.csv --tag "reference=$ref" --tag defaults=2026-11-23
      $P studies/ablation_table.py "$r=$ref" "$r=dcee-cl" "$r-mcts-today=dcee-mcts" \
        --csv docs/results/lbm-held-out-100/paired.csv --tag "reference=$ref" --tag defaults=2026-11-27
      $P studies/ablation_table.py "$r-bf=$ref" "$r-bf=dcee-cl" "$r-mcts-bf=dcee-mcts" \
        --csv docs/results/lbm-held-out-100/paired.csv --tag "reference=$ref" --tag defaults=2026-11-27b
    done
    # the backflow member against the defaults just before it, search by search
    for pair in "$r:$r-bf" "$r-mcts-today:$r-mcts-bf" "$r-bf:$r-radius" "$r-bf:$r-radius-prior"; do
      $P studies/pair_campaigns.py "${pair%%:*}" "${pair#*:}" \
        --csv docs/results/lbm-held-out-100/backflow_vs_before.csv --tag truth_model=lbm
    done
    # today's defaults against those before, search by search
    $P studies/pair_campaigns.py "$r-nsl25" "$r" --csv docs/results/lbm-held-out-100/today_vs_before.csv \
      --tag truth_model=lbm
    # the disc member at prior odds 9:1 with the mixture's region against the backflow member alone
    rm -f docs/results/lbm-held-out-100/disc_vs_before.csv
    for pair in "$r-bf:$r-dm" "$r-bf:$r-dm-info" "$r-mcts-bf:$r-mcts-dm"; do
      $P studies/pair_campaigns.py "${pair%%:*}" "${pair#*:}" \
        --csv docs/results/lbm-held-out-100/disc_vs_before.csv --tag truth_model=lbm
    done
    # dcee-cl looking two moves ahead (a planner option) against each planner at today's defaults
    rm -f docs/results/lbm-held-out-100/horizon_vs_default.csv
    for ref in dcee-cl infotaxis dcee-mcts; do
      $P studies/pair_campaigns.py "$r-dm=$ref" "$r-dm-h2" --as "dcee-cl:horizon=2=$ref" \
        --csv docs/results/lbm-held-out-100/horizon_vs_default.csv --tag truth_model=lbm
    done
    $P studies/worst_searches.py "$r-dm=dcee-cl" "$r-dm-info=infotaxis" --out docs/figures/lbm-held-out-worst.png
    $P studies/upwind_detections.py "$r-dm=dcee-cl" "$r-dm-info=infotaxis" "$r-mcts-dm=dcee-mcts" \
      "$r-dm-h2=dcee-cl:horizon=2" \
      "$r-bf=dcee-cl" "$r-bf=infotaxis" "$r-mcts-bf=dcee-mcts" \
      "$r=dcee-cl" "$r=infotaxis" "$r-nsl25=dcee-cl" \
      "$r-nsl25=infotaxis" "$r-decay=dcee-cl" "$r-mcts=dcee-mcts" "$r-nsl=dcee-cl"
    $P studies/publish_tables.py ;;
  source-count)  # issue 45: an unknown number of releases, dcee-cl, 100 held-out configurations of two and of three releases (docs/multi-source.md)
    count_campaigns dcee-cl "" "${C0[@]}"
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-one)  # issue 45: one release, the count unknown (0-3) against the one-release filter, 100 held-out configurations (docs/multi-source.md)
    for ARM in unknown-count known-count; do
      $D bench --suite "one-source-$ARM-held-out-100" --repeats 1 --strategies dcee-cl \
        "${C0[@]}" --workers "${WORKERS:-2}" --out "results/one-source-$ARM-held-out-100"
    done
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-wind-unknown)  # issue 45: two releases with the wind unknown too, the first 50 held-out configurations (docs/multi-source.md)
    $D bench --suite two-source-wind-unknown-held-out-50 --repeats 1 --strategies dcee-cl \
      "${C0[@]}" --workers "${WORKERS:-2}" --out results/two-source-wind-unknown-held-out-50
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-turbulent)  # issue 45: two releases in the filament and the puff truths, the fluctuation likelihood with one reading model (docs/multi-source.md)
    for T in filament puffs; do
      $D bench --suite two-source-held-out-100 --repeats 1 --strategies dcee-cl --truth $T \
        --likelihood fluctuation --set estimator.calm_prior=0 --set 'estimator.learn={}' \
        --workers "${WORKERS:-2}" --out results/two-source-$T-held-out-100
    done
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-infotaxis)  # issue 45: infotaxis on the joint belief, the same 100 two-release held-out configurations (docs/multi-source.md)
    $D bench --suite two-source-held-out-100 --repeats 1 --strategies infotaxis \
      "${C0[@]}" --workers "${WORKERS:-2}" --out results/two-source-held-out-100-infotaxis
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-mcts)  # issue 45: the tree search on the joint belief, the same 100 held-out configurations of two and of three releases (docs/multi-source.md)
    count_campaigns dcee-mcts -mcts "${C0[@]}"
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-paper-scale)  # issue 45: the three-release held-out campaign at the paper's 20,000 particles
    $D bench --suite three-source-held-out-100 --repeats 1 --strategies dcee-cl --particles 20000 \
      "${C0[@]}" --workers "${WORKERS:-2}" --out results/three-source-held-out-100-20k
    source_count_tables
    $P studies/publish_tables.py ;;
  source-count-timing)  # issue 45: decision and update time with the count unknown against one release (idle machine, one pinned core)
    $P studies/source_count_timing.py --out docs/results/source-count/timing.csv
    $P studies/publish_tables.py ;;
  source-count-tune)  # issue 45: the same on the tuning range random2/3:1-60 at the fixed altitude (never reported as a result)
    for N in two three; do
      $D bench --suite "$N-source-tune" --repeats 1 --strategies dcee-cl "${C0[@]}" \
        --workers "${WORKERS:-2}" --out "results/$N-source-tune"
    done
    $P studies/source_count_table.py results/two-source-tune results/three-source-tune ;;
  source-count-tune-climb)  # issue 45: the tuning range random3/2:1-60 with the UAV free to climb (agent.climb = 1, today's default with the count unknown; -60-climb in docs/results/source-count-tune)
    for N in three two; do
      $D bench --suite "$N-source-tune" --repeats 1 --strategies dcee-cl \
        --workers "${WORKERS:-2}" --out "results/$N-source-tune-60-climb"
    done
    $P studies/source_count_table.py results/three-source-tune-60-climb \
      results/two-source-tune-60-climb --csv docs/results/source-count-tune/searches.csv ;;
  source-count-climb)  # issue 45: dcee-cl at today's defaults (the UAV free to climb with the count unknown), the 100 held-out configurations of three and of two releases (docs/multi-source.md)
    count_campaigns dcee-cl -climb
    source_count_tables
    $P studies/publish_tables.py ;;
  publish)  # the tables of README.md, docs/index.md, docs/results.md from docs/results/
    $P studies/publish_tables.py ;;
  stonesoup-mcts)  # our tree search against Stone Soup's MCTS on its own example, 10 seeds
    $P studies/stonesoup_mcts_study.py results/stonesoup-mcts --seeds 10 ;;
  perf)  # the speed tables (README, docs/performance.md) from stored runs; run it with nothing
    # else on the machine (each output records the load beside it and is marked shared if not)
    mkdir -p docs/results/perf
    $D perf --json docs/results/perf/workloads.json
    $D perf --compare-stonesoup --decisions 20 --repeats 5 --json docs/results/perf/stonesoup-ste.json
    $P studies/kernel_speedup.py --before f52a5b6 --json docs/results/perf/kernel-speedup.json
    $P studies/kernel_speedup.py --before cae7e4f --json docs/results/perf/kernel-speedup-blas.json
    $P studies/move_speedup.py --before 825da4d --rounds 5 --json docs/results/perf/move-speedup.json
    $P studies/horizon_timing.py --rounds 2 --json docs/results/perf/horizon-timing.json
    $P studies/demo_decision.py --before cae7e4f --json docs/results/perf/demo-decision.json
    $P studies/search_speed.py --before 31f49fd --json docs/results/perf/search-speed.json
    rm -rf results/perf-stonesoup-mcts  # every seed timed in this run
    $P studies/stonesoup_mcts_study.py results/perf-stonesoup-mcts --seeds "${MCTS_SEEDS:-3}" \
      --json docs/results/perf/stonesoup-mcts.json
    $P studies/publish_tables.py ;;
  search-speed)  # whole searches of the five default planners, before/after issue 46's second round
    $P studies/search_speed.py --before 31f49fd --json docs/results/perf/search-speed.json
    $P studies/publish_tables.py ;;
  study-600)  # the 600-search study's wall time (five default planners x 120, 2 workers; idle machine)
    rm -rf results/study-600
    start=$(date +%s)
    $D bench --suite paper --repeats 10 --workers 2 --out results/study-600
    $P studies/study_wall.py results/study-600 --wall $(( $(date +%s) - start )) \
      --json docs/results/perf/study-600.json
    $P studies/publish_tables.py ;;
  precision-single)  # dcee-cl in single precision beside double: the public study's 120 searches, paired
    $D bench --suite paper --repeats 10 --strategies dcee-cl,dcee-cl:precision=single \
      --workers "${WORKERS:-2}" --out results/precision-single
    report precision-single
    $P studies/collect_metrics.py --out docs/results/precision-single results/precision-single
    rm -f docs/results/precision-single/paired.csv  # ablation_table appends
    $P studies/ablation_table.py results/precision-single=dcee-cl \
      results/precision-single=dcee-cl:precision=single --csv docs/results/precision-single/paired.csv
    $P studies/publish_tables.py ;;
  agreement)  # decisions with precision=single and interpolated against exact double (20,000 particles)
    $P studies/decision_agreement.py --precision single \
      --strategies dcee,infotaxis,entrotaxis,dcee-cl --json docs/results/perf/agreement-single.json
    $P studies/decision_agreement.py --precision interpolated \
      --strategies dcee,infotaxis,entrotaxis,dcee-cl \
      --json docs/results/perf/agreement-interpolated.json
    # every decision of the demo's whole search (and of paper:5 and paper:12), not only the first 40
    $P studies/decision_agreement.py --precision interpolated --strategies dcee-cl --seeds 1 \
      --steps 450 --json docs/results/perf/agreement-interpolated-full.json
    # infotaxis and entrotaxis: the one-pass sums against the matrix-product path, every decision
    $P studies/one_pass_agreement.py --json docs/results/perf/one-pass-agreement.json
    $P studies/publish_tables.py ;;
  precision-interpolated)  # dcee-cl with interpolated sums beside exact double: the public study's 120 searches, paired
    $D bench --suite paper --repeats 10 \
      --strategies dcee-cl:precision=double,dcee-cl:precision=interpolated \
      --workers "${WORKERS:-2}" --out results/precision-interpolated
    report precision-interpolated
    $P studies/collect_metrics.py --out docs/results/precision-interpolated results/precision-interpolated
    rm -f docs/results/precision-interpolated/paired.csv  # ablation_table appends
    $P studies/ablation_table.py results/precision-interpolated=dcee-cl:precision=double \
      results/precision-interpolated=dcee-cl:precision=interpolated \
      --csv docs/results/precision-interpolated/paired.csv
    $P studies/publish_tables.py ;;
  --list)
    sed -n 's/^  \([a-z-]*\)) *# \(.*\)/\1\t\2/p' "$0" ;;
  *)
    echo "studies/run.sh: error: unknown study ${1@Q}; see bash studies/run.sh --list" >&2
    exit 2 ;;
esac
exit
}
