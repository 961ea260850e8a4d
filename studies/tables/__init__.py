"""The generated tables by name (studies/publish_tables.py writes them between the markers
on the pages), one module per study family."""

from __future__ import annotations

from collections.abc import Callable

from dcee.scenarios import REGION_FLOOR_DEFAULT
from studies.tables.gaden import (
    gaden_fit_table,
    gaden_rooms_table,
    gaden_starts_table,
    gaden_timing_table,
)
from studies.tables.geo import REAL_SITE_FOLDER, geo_site_table
from studies.tables.headline import headline_table
from studies.tables.held_out import held_out_table, others_table, paired_table
from studies.tables.lbm import (
    lbm_endgame_table,
    lbm_near_source_table,
    lbm_statistics_table,
)
from studies.tables.paper import (
    anemometer_table,
    lab_table,
    public_table,
    stop_rule_table,
    team_table,
)
from studies.tables.performance import (
    agreement_single_table,
    kernel_speedup_table,
    precision_single_table,
    search_speed_table,
    speed_table,
    stonesoup_runs_table,
)
from studies.tables.robustness import (
    fuzz_readers_table,
    soak_faults_table,
    soak_run_table,
    soak_table,
    soak_worst_table,
)
from studies.tables.sites import (
    lee_viscosity_table,
    site_upwind_table,
    sites_table,
    sites_walls_table,
    sites_walls_timing_table,
    wander_release_table,
)
from studies.tables.source_count import _source_count, source_count_timing_table
from studies.tables.sparse import sparse_table
from studies.tables.three_d import (
    lbm3d_altitude_table,
    lbm3d_plume_table,
    lbm3d_search_table,
    lbm3d_slice_oracle_table,
    lbm3d_slice_probes_table,
    lbm3d_slice_tails_table,
    lbm3d_slice_zeros_table,
    lbm3d_store_tune_table,
    lbm3d_surface_tune_table,
    lbm3d_timing_table,
)
from studies.tables.tuning import (
    backflow_tuning_table,
    horizon_tuning_table,
    learn_tuning_table,
    lookahead3_tuning_table,
    mixture_prior_table,
    mixture_region_table,
    radius_prior_table,
    region_floor_table,
    release_area_table,
    source_radius_tuning_table,
)
from studies.tables.turbulent import cross_truth_table, turbulent_table

TABLES: dict[str, Callable[[], str]] = {
    "gaden-fit": gaden_fit_table,
    "gaden-rooms": gaden_rooms_table,
    "geo-site": geo_site_table,
    "geo-site-fontvieille": lambda: geo_site_table(REAL_SITE_FOLDER),
    "lbm3d-sparse-tune": sparse_table,
    "gaden-starts": gaden_starts_table,
    "gaden-timing": gaden_timing_table,
    "fuzz-readers": fuzz_readers_table,
    "soak": soak_table,
    "soak-faults": soak_faults_table,
    "soak-run": soak_run_table,
    "soak-worst": soak_worst_table,
    "lbm3d-plume": lbm3d_plume_table,
    "lbm3d-search": lbm3d_search_table,
    "lbm3d-altitudes": lbm3d_altitude_table,
    "lbm3d-timing": lbm3d_timing_table,
    "lbm3d-surface-tune": lbm3d_surface_tune_table,
    "lbm3d-store-tune": lbm3d_store_tune_table,
    "lbm3d-slice-probes": lbm3d_slice_probes_table,
    "lbm3d-slice-oracle": lbm3d_slice_oracle_table,
    "lbm3d-slice-zeros": lbm3d_slice_zeros_table,
    "lbm3d-slice-tails": lbm3d_slice_tails_table,
    "source-count": lambda: _source_count("table"),
    "source-count-latest": lambda: _source_count("table_latest"),
    "source-count-worst": lambda: _source_count("worst"),
    "source-count-paired": lambda: _source_count("paired"),
    "source-count-observable": lambda: _source_count("observable"),
    "source-count-timing": source_count_timing_table,
    "learn-tuning": learn_tuning_table,
    "backflow-tuning": backflow_tuning_table,
    "source-radius-tuning": source_radius_tuning_table,
    "lbm-near-source": lbm_near_source_table,
    "lbm-endgame": lbm_endgame_table,
    "horizon-tuning": horizon_tuning_table,
    "lookahead3-tuning": lookahead3_tuning_table,
    "region-floor-tuning": lambda: region_floor_table(
        "tuning-region-floor-13-40/coverage.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "region-floor-lbm": lambda: region_floor_table(
        "lbm-held-out-100/region_floor.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "region-floor-lbm-infotaxis": lambda: region_floor_table(
        "lbm-held-out-100/region_floor_infotaxis.csv", REGION_FLOOR_DEFAULT["fluctuation"]
    ),
    "cross-truth": cross_truth_table,
    "cross-truth-latest": lambda: cross_truth_table(latest_only=True),
    "radius-prior-point": lambda: radius_prior_table("point"),
    "radius-prior-area": lambda: radius_prior_table("area"),
    "mixture-region": mixture_region_table,
    "mixture-prior": mixture_prior_table,
    "release-area": release_area_table,
    "lbm-statistics": lbm_statistics_table,
    "headline": headline_table,
    "headline-docs": lambda: headline_table(""),
    "wind-known": public_table("paper-source"),
    "full-unknown": public_table("paper-full"),
    "held-out": held_out_table,
    "held-out-paired": paired_table,
    "held-out-others": others_table,
    "turbulent": turbulent_table,
    "team": team_table,
    "lab": lab_table,
    "stop-rule": stop_rule_table,
    "anemometer": anemometer_table,
    "sites": sites_table,
    "sites-walls": sites_walls_table("sites-walls"),
    "sites-walls-tune": sites_walls_table("sites-walls-tune", all_only=True),
    "sites-walls-planners": sites_walls_table("sites-walls-planners", all_only=True),
    "sites-walls-lookahead": sites_walls_table("sites-walls-lookahead"),
    "sites-walls-passage": sites_walls_table("sites-walls-passage"),
    "sites-walls-timing": sites_walls_timing_table,
    "wander-release": wander_release_table,
    "site-upwind-gas": site_upwind_table,
    "lee-viscosity": lee_viscosity_table,
    "speed": speed_table,
    "stonesoup-runs": stonesoup_runs_table,
    "search-speed": search_speed_table,
    "kernel-speedup": kernel_speedup_table,
    "kernel-speedup-blas": lambda: kernel_speedup_table("kernel-speedup-blas"),
    "agreement-single": agreement_single_table,
    "precision-single": precision_single_table,
    "agreement-interpolated": lambda: agreement_single_table(
        "agreement-interpolated", "agreement-interpolated-full"
    ),
    "precision-interpolated": lambda: precision_single_table(
        "precision-interpolated",
        "dcee-cl:precision=double",
        "dcee-cl:precision=interpolated",
        "interpolated",
    ),
}
