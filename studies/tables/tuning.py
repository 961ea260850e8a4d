"""The tuning rounds of the fluctuation likelihood and the planners on the tuning range
(random:13-40): each candidate paired search by search with the defaults it was measured
against (recipes tune-*, mixture-region*, region-floor-held-out*, lookahead*)."""

from __future__ import annotations

from collections.abc import Iterator

import pandas as pd

from studies.tables.common import (
    RESULTS,
    table,
)


def learn_tuning_table() -> str:
    """Reading-model candidates against the defaults before 2026-11-27 (a 2.5 m near-source
    fall, repeat power 1/4) on the tuning range (filament and puffs only: the truths defaults may
    be chosen on), paired by search (studies/precision_variants.py's rows in
    docs/results/tuning-*-13-40; the old defaults ran in the first two, reading for reading the
    same). The last candidate was the default until the backflow member joined it."""
    frame = pd.concat(
        pd.read_csv(RESULTS / folder / "variants.csv")
        for folder in (
            "tuning-learn-13-40",
            "tuning-log-sd-13-40",
            "tuning-near-sd-13-40",
            "tuning-nsl05-13-40",
            "tuning-nsl05-rp05-13-40",
        )
    )
    names = {
        "base": "defaults before 2026-11-27 (2.5 m fall, repeat power 1/4)",
        "decay": "`learn = {decay = [1, 0.5]}`",
        "both": "`learn = {meander = [0.15, 0.3, 0.6], log_sd = [1.3, 2]}`",
        "nsl": "`learn = {near_source_length = [2.5, 0]}`",
        "sd": "`learn = {log_sd = [1.3, 2, 3]}`",
        "nearsd": "`learn = {log_sd_near = [0, 3, 6]}`, `log_sd_length = 1.5`",
        "nsl05": "`near_source_length = 0.5` (fixed, not learned)",
        "nsl05rp05": "the defaults of 2026-11-27 (before the backflow member): "
        "`near_source_length = 0.5`, `repeat_power = 0.5`",
    }
    order = ("base", "decay", "both", "nsl", "sd", "nearsd", "nsl05", "nsl05rp05")
    return _variant_table(frame, names, order, "the defaults before 2026-11-27")


def backflow_tuning_table() -> str:
    """Gas upwind of the release, learned, against today's defaults on the tuning range, both
    flown in one run (docs/results/tuning-backflow-13-40; the rule in its README)."""
    frame = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    names = {
        "base": "defaults of 2026-11-27 before the backflow member",
        "backflow": "**today's defaults**: `learn = {backflow = [0, 0.05]}`",
    }
    return _variant_table(frame, names, ("base", "backflow"), "the defaults before it")


def source_radius_tuning_table() -> str:
    """A release spread over a disc, learned, against the defaults it was measured against (the
    backflow rows of docs/results/tuning-backflow-13-40: the same searches), on the tuning
    range (docs/results/tuning-source-radius-13-40; the rule in its README)."""
    before = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    before = before[before["variant"] == "backflow"].assign(variant="base")
    frame = pd.concat(
        [before, pd.read_csv(RESULTS / "tuning-source-radius-13-40" / "variants.csv")]
    )
    names = {
        "base": "`learn = {backflow = [0, 0.05]}` (the defaults it was measured against)",
        "radius": "`learn = {backflow = [0, 0.05], source_radius = [0, 1]}`",
    }
    return _variant_table(frame, names, ("base", "radius"), "the defaults it was measured against")


def radius_prior_table(release: str) -> str:
    """Disc members on the tuning range, each search paired with today's defaults on the same
    configuration: on the point releases (``release="point"``; today's defaults: the backflow
    rows of docs/results/tuning-backflow-13-40) or on the releases over an area (``"area"``,
    ``puff_radius`` 0.5 m; today's defaults: the ``area`` rows of
    docs/results/tuning-area-release-13-40). The rule: docs/results/tuning-radius-prior-13-40."""
    if release == "point":
        base = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
        base = base[base["variant"] == "backflow"]
        radius = pd.read_csv(RESULTS / "tuning-source-radius-13-40" / "variants.csv")
        prior, label = "prior", "point releases"
    else:
        area = pd.read_csv(RESULTS / "tuning-area-release-13-40" / "variants.csv")
        base = area[area["variant"] == "area"]
        radius = area[area["variant"] == "area-radius"].assign(variant="radius")
        prior, label = "area-prior", "releases over an area (`puff_radius = 0.5`)"
    candidate = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    candidate = candidate[candidate["variant"] == prior].assign(variant="prior")
    frame = pd.concat([base.assign(variant="base"), radius, candidate])
    names = {
        "base": f"the defaults of 2026-11-27 (b), {label}",
        "radius": "`learn = {backflow = [0, 0.05], source_radius = [0, 1]}` (equal priors)",
        "prior": "the same with `learn_prior = {source_radius = [0.9, 0.1]}`",
    }
    return _variant_table(
        frame, names, ("base", "radius", "prior"), "the defaults of 2026-11-27 (b)"
    )


def horizon_tuning_table() -> str:
    """``dcee-cl:horizon=2`` on the tuning range, each search paired with ``dcee-cl`` one move
    ahead at the defaults of 2026-11-27 (c) (the ``prior`` rows of
    docs/results/tuning-radius-prior-13-40, their 95 % region the mixture's, as
    docs/results/mixture-region-prior-13-40 recomputed it). The rule, by which two moves became
    the default of 2026-11-29 (``search.lookahead``): docs/results/tuning-horizon-13-40."""
    key = ["truth", "scenario", "seed"]
    base = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    base = base[base["variant"] == "prior"].drop(columns="truth_in_95")
    region = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    region = region[region["variant"] == "prior"][[*key, "mixture_in_95"]]
    base = base.merge(region, on=key).rename(columns={"mixture_in_95": "truth_in_95"})
    candidate = pd.read_csv(RESULTS / "tuning-horizon-13-40" / "variants.csv")
    frame = pd.concat([base.assign(variant="base"), candidate.assign(variant="horizon2")])
    names = {
        "base": "`dcee-cl` one move ahead (the defaults of 2026-11-27 (c))",
        "horizon2": "`dcee-cl:horizon=2` (two moves ahead: the default of 2026-11-29)",
    }
    return _variant_table(frame, names, ("base", "horizon2"), "`dcee-cl` one move ahead", "planner")


def lookahead3_tuning_table() -> str:
    """``search.lookahead = 3`` on the tuning range, each search paired with ``dcee-cl`` two moves
    ahead (the default of 2026-11-29: the ``horizon2`` rows of docs/results/tuning-horizon-13-40,
    the same planner decision for decision). The rule, by which three moves became the default:
    docs/results/tuning-lookahead3-13-40."""
    base = pd.read_csv(RESULTS / "tuning-horizon-13-40" / "variants.csv")
    candidate = pd.read_csv(RESULTS / "tuning-lookahead3-13-40" / "variants.csv")
    frame = pd.concat([base.assign(variant="base"), candidate.assign(variant="lookahead3")])
    names = {
        "base": "`dcee-cl` two moves ahead (the default of 2026-11-29)",
        "lookahead3": "`search.lookahead = 3` (three moves ahead: today's default)",
    }
    return _variant_table(
        frame, names, ("base", "lookahead3"), "`dcee-cl` two moves ahead", "planner"
    )


def region_floor_table(path: str, chosen: float | None = None) -> str:
    """The share of searches with the truth in the 95 % region at each model-discrepancy floor
    (studies/region_floor.py's table at ``path`` under docs/results), one column per truth, and
    the floored region's median RMS radius; the ``chosen`` floor in bold."""
    frame = pd.read_csv(RESULTS / path)
    truths = list(dict.fromkeys(frame["truth"]))
    rows = []
    for f, part in frame.groupby("floor", sort=True):
        cells = []
        for t in truths:
            r = part[part["truth"] == t].iloc[0]
            cells.append(
                f"{int(r['inside'])}/{int(r['n'])}, {100 * r['share']:.0f} % "
                f"[{100 * r['lo']:.0f}, {100 * r['hi']:.0f}]"
            )
        radius = part[part["truth"] == truths[-1]].iloc[0]["median_radius"]
        label = f"{f:.2f}"
        if chosen is not None and abs(f - chosen) < 1e-9:
            label = f"**{label}** (the default)"
        rows.append([label, *cells, f"{radius:.2f}"])
    names = {"all": "both truths"}
    header = [
        "floor σ (m)",
        *[f"{names.get(t, t)}: truth in 95 % region" for t in truths],
        f"median RMS radius of the region, {names.get(truths[-1], truths[-1])} (m)",
    ]
    return table(header, rows)


def _by_truth(rows: pd.DataFrame) -> Iterator[tuple[str, pd.DataFrame]]:
    """(truth, rows) for the filament, the puffs and both together (the last only when both
    are there: one truth's own row says it all); truths without rows are skipped."""
    for truth in ("filament", "puffs", "both truths"):
        part = rows if truth == "both truths" else rows[rows["truth"] == truth]
        if truth == "both truths" and rows["truth"].nunique() < 2:
            continue
        if not part.empty:
            yield truth, part


def _gained_lost(new: pd.Series, old: pd.Series) -> tuple[int, int, float]:
    """Paired yes/no outcomes (bool Series, aligned): (new only, old only, exact binomial
    p of the discordant pairs, McNemar's exact test; 1 when there are none)."""
    from scipy.stats import binomtest

    gained, lost = int((new & ~old).sum()), int((old & ~new).sum())
    return gained, lost, binomtest(gained, gained + lost).pvalue if gained + lost else 1.0


def mixture_region_table() -> str:
    """The truth in the selected member's 95 % region and in the reading models' mixture's, on
    the same searches (docs/results/mixture-region-13-40, studies/mixture_region.py)."""

    frame = pd.read_csv(RESULTS / "mixture-region-13-40" / "searches.csv")
    releases = {"radius": "point", "area-radius": "area (`puff_radius = 0.5`)"}
    rows = []
    for variant, release in releases.items():
        for truth, part in _by_truth(frame[frame["variant"] == variant]):
            sel, mix = part["truth_in_95"].astype(bool), part["mixture_in_95"].astype(bool)
            gained, lost, p = _gained_lost(mix, sel)
            rows.append(
                [
                    release,
                    truth,
                    str(len(part)),
                    f"{100 * sel.mean():.0f} %",
                    f"{100 * mix.mean():.0f} %",
                    f"+{gained} / −{lost} (p = {p:.2g})",
                ]
            )
    header = [
        "releases",
        "truth",
        "n",
        "truth in the selected member's 95 % region",
        "in the mixture's",
        "mixture against selected, gained / lost (exact binomial)",
    ]
    return table(header, rows)


def mixture_prior_table() -> str:
    """The default since 2026-11-27 (c), disc members at prior odds 9 : 1 with the mixture's
    region, against the defaults before it on the same configurations, point and area releases
    (docs/results/mixture-region-prior-13-40; the rule in its README)."""
    from scipy.stats import wilcoxon

    frame = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    before = pd.read_csv(RESULTS / "tuning-backflow-13-40" / "variants.csv")
    area = pd.read_csv(RESULTS / "tuning-area-release-13-40" / "variants.csv")
    bases = {
        "prior": ("point", before[before["variant"] == "backflow"]),
        "area-prior": ("area (`puff_radius = 0.5`)", area[area["variant"] == "area"]),
    }
    rows = []
    for variant, (release, base) in bases.items():
        both = frame[frame["variant"] == variant].merge(
            base, on=["truth", "scenario", "seed"], suffixes=("", "_before")
        )
        for truth, part in _by_truth(both):
            old, new = part["truth_in_95_before"].astype(bool), part["mixture_in_95"].astype(bool)
            gained, lost, p = _gained_lost(new, old)
            diff = part["final_rmse"] - part["final_rmse_before"]
            p_rmse = wilcoxon(diff).pvalue if (diff != 0).any() else 1.0
            acquired = part["acquired"].astype(bool).sum()
            rows.append(
                [
                    release,
                    truth,
                    str(len(part)),
                    f"{acquired} / {part['acquired_before'].astype(bool).sum()}",
                    f"{100 * old.mean():.0f} %",
                    f"{100 * part['truth_in_95'].astype(bool).mean():.0f} %",
                    f"**{100 * new.mean():.0f} %**",
                    f"+{gained} / −{lost} (p = {p:.2g})",
                    f"{diff.median():+.2f} m (p = {p_rmse:.2g})",
                ]
            )
    header = [
        "releases",
        "truth",
        "n",
        "acquired (today's / before)",
        "truth in 95 %, before",
        "today's, selected member's region",
        "today's, the mixture's region",
        "region against before, gained / lost (exact binomial)",
        "final RMSE against before, paired median (Wilcoxon)",
    ]
    return table(header, rows)


def release_area_table() -> str:
    """Today's defaults (since 2026-11-27 (c)) on the tuning range released at a point, over
    0.5 m and over 1 m (``truth.model.puff_radius``): is the lbm failure an area-release one?
    (docs/results/mixture-region-prior-13-40, whose point and 0.5 m searches are today's
    defaults', and docs/results/tuning-area-release-1m-13-40)."""
    today = pd.read_csv(RESULTS / "mixture-region-prior-13-40" / "searches.csv")
    today = today.assign(truth_in_95=today["mixture_in_95"])  # the region every summary now has
    # the same searches, flown first by tuning-radius-prior, which recorded the along-wind error
    first = pd.read_csv(RESULTS / "tuning-radius-prior-13-40" / "variants.csv")
    today = today.merge(first[["variant", "truth", "scenario", "along"]], how="left")
    wide = pd.read_csv(RESULTS / "tuning-area-release-1m-13-40" / "variants.csv")
    releases = {
        "point (`puff_radius = 0.1`)": today[today["variant"] == "prior"],
        "over 0.5 m (`puff_radius = 0.5`)": today[today["variant"] == "area-prior"],
        "over 1 m (`puff_radius = 1.0`)": wide[wide["variant"] == "area1"],
    }
    rows = []
    for release, frame in releases.items():
        for truth, part in _by_truth(frame):
            n = len(part)
            rows.append(
                [
                    release,
                    truth,
                    str(n),
                    f"{int(part['acquired'].astype(bool).sum())}/{n}",
                    f"{part['final_rmse'].median():.2f}",
                    f"{100 * part['truth_in_95'].astype(bool).mean():.0f} %",
                    f"{part['along'].median():+.2f}",
                ]
            )
    header = [
        "released",
        "truth",
        "n",
        "acquired",
        "median final RMSE (m)",
        "truth in 95 % (the mixture's region)",
        "median along-wind error (m)",
    ]
    return table(header, rows)


def _variant_table(
    frame: pd.DataFrame, names: dict, order: tuple, base_name: str, kind: str = "reading model"
) -> str:
    """Rows per variant and truth (and both truths), each variant paired by search with the
    variant ``base``: acquisition, median final RMSE, share in the 95 % region, along-wind
    error; Wilcoxon on the final RMSE, exact binomial on the region gained / lost."""
    from scipy.stats import wilcoxon

    key = ["truth", "scenario", "seed"]
    frame = frame.drop_duplicates(["variant", *key])
    base = frame[frame["variant"] == "base"]
    rows = []
    for variant in order:
        for truth, part in _by_truth(frame[frame["variant"] == variant]):
            n = len(part)
            paired = "—"
            if variant != "base":
                joined = part.merge(base, on=key, suffixes=("", "_base"))
                diff = joined["final_rmse"] - joined["final_rmse_base"]
                p_rmse = wilcoxon(diff).pvalue if (diff != 0).any() else 1.0
                gained, lost, p_cov = _gained_lost(
                    joined["truth_in_95"], joined["truth_in_95_base"]
                )
                paired = (
                    f"{diff.median():+.2f} m (Wilcoxon p = {p_rmse:.2g}); 95 % region "
                    f"+{gained} / −{lost} (p = {p_cov:.2g}), {len(joined)} pairs"
                )
            rows.append(
                [
                    names[variant],
                    truth,
                    str(n),
                    f"{int(part['acquired'].sum())}/{n}",
                    f"{part['final_rmse'].median():.2f}",
                    f"{100 * part['truth_in_95'].mean():.0f} %",
                    f"{part['along'].median():+.2f}",
                    paired,
                ]
            )
    header = [
        kind,
        "truth",
        "n",
        "acquired",
        "median final RMSE (m)",
        "truth in 95 %",
        "median along-wind error (m)",
        f"paired with {base_name}: final RMSE, median difference; 95 % region gained / lost",
    ]
    return table(header, rows)
