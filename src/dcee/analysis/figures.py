"""Figures of one search: plume map, particles, trajectory, readings, RMSE over time."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm

from dcee.estimation.multi_source_kernels import source_rows

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from dcee.runs import EpisodeResult
    from dcee.scenarios import Scenario
    from dcee.simulation.truth import TruthModel


def plume_map(
    truth: TruthModel, scenario: Scenario, time: float, resolution: int = 160
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(xs, ys, C) of the truth at the sensor's altitude; C has shape (len(ys), len(xs))."""
    lo, hi = scenario.volume.low, scenario.volume.high
    xs = np.linspace(lo[0], hi[0], resolution)
    ys = np.linspace(lo[1], hi[1], resolution)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.column_stack([gx.ravel(), gy.ravel(), np.full(gx.size, scenario.agent.start[2])])
    return xs, ys, truth.field(pts, time).reshape(gy.shape)


def _draw_site(ax: plt.Axes, scenario: Scenario) -> None:
    """The ``[world]``'s blocked cells (obstacles and no-go zones, grown by the grid's half
    cell and the clearance, as the planners see them), hatched grey."""
    site = scenario.make_site()
    if site is None or not site.blocked.any():
        return
    ny, nx = site.shape
    r = site.resolution
    xs = site.origin[0] + np.arange(nx + 1) * r
    ys = site.origin[1] + np.arange(ny + 1) * r
    ax.pcolormesh(
        xs,
        ys,
        np.ma.masked_where(~site.blocked, np.ones(site.shape)),
        cmap="Greys",
        vmin=0,
        vmax=1.6,
        shading="flat",
        rasterized=True,
        zorder=2,
    )
    ax.plot([], [], "s", color="0.6", label="obstacle / no-go zone")


RELEASE_COLOURS = ("tab:green", "tab:purple", "tab:olive", "tab:pink")
"""The particles' colour of each release of a search whose count was unknown."""


def _draw_map(
    ax: plt.Axes,
    result: EpisodeResult,
    scenario: Scenario,
    truth: TruthModel,
    until: float,
    particles: np.ndarray,
) -> None:
    thr = scenario.sensor.threshold
    xs, ys, conc = plume_map(truth, scenario, until)
    conc = np.clip(conc, thr / 10, None)
    mesh = ax.pcolormesh(
        xs,
        ys,
        conc,
        norm=LogNorm(vmin=thr / 10, vmax=max(conc.max(), 10 * thr)),
        cmap="YlOrBr",
        shading="auto",
        rasterized=True,
    )
    if conc.min() < thr < conc.max():
        ax.contour(xs, ys, conc, levels=[thr], colors="k", linewidths=0.6, linestyles="--")
    _draw_site(ax, scenario)
    recs = [r for r in result.records if r["time"] <= until + 1e-9]
    # several releases (a count bank's answer): each release's particles in its own colour
    releases = source_rows(particles) if particles.shape[1] > 8 else particles[None, :, :3]
    for j, rel in enumerate(releases):
        ax.scatter(
            rel[:, 0],
            rel[:, 1],
            s=1.0,
            c=RELEASE_COLOURS[j % len(RELEASE_COLOURS)],
            alpha=0.35,
            lw=0,
            label="particles (source hypotheses)"
            if len(releases) == 1
            else f"release {j + 1} particles",
        )
    px = np.array([r["x"] for r in recs])
    py = np.array([r["y"] for r in recs])
    robot = np.array([r.get("robot", 0) for r in recs])
    robots = np.unique(robot)
    for k in robots:
        on = robot == k
        label = "trajectory" if len(robots) == 1 else f"robot {k} trajectory"
        ax.plot(px[on], py[on], "-", color=_robot_colour(k), lw=0.8, alpha=0.8, label=label)
    det = np.array([r["detection"] for r in recs])
    z = np.array([r["reading"] for r in recs])
    ax.scatter(px[~det], py[~det], s=4, c="0.35", lw=0, label="non-detection")
    if det.any():
        size = 10 + 60 * np.sqrt(z[det] / z[det].max())
        ax.scatter(
            px[det],
            py[det],
            s=size,
            facecolors="none",
            edgecolors="tab:blue",
            lw=0.8,
            label="detection (size ∝ √reading)",
        )
    sources = scenario.truth.source_locations()
    label = "true source" if len(sources) == 1 else f"true sources ({len(sources)})"
    ax.plot(sources[:, 0], sources[:, 1], "*", ms=14, mec="k", mfc="gold", ls="none", label=label)
    last = recs[-1]
    found = result.summary.get("estimated_sources")
    if found is not None:  # the count was unknown: the answer is a set
        est = np.array(found, dtype=float).reshape(-1, 3)
        ax.plot(
            est[:, 0],
            est[:, 1],
            "P",
            ms=9,
            mec="k",
            mfc="tab:cyan",
            ls="none",
            label=f"estimated releases (K̂ = {len(est)})",
        )
    else:
        ax.plot(
            last["mean_x"],
            last["mean_y"],
            "P",
            ms=9,
            mec="k",
            mfc="tab:cyan",
            label="posterior mean",
        )
    starts = scenario.starts()
    ax.plot(starts[:, 0], starts[:, 1], "x", ms=9, color="k", mew=2, ls="none", label="start")
    ax.set_xlim(scenario.volume.low[0], scenario.volume.high[0])
    ax.set_ylim(scenario.volume.low[1], scenario.volume.high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"t = {until:.0f} s, RMSE {last['rmse']:.2f} m", loc="left")
    _draw_compass(ax, scenario.truth.phi)
    if scenario.world.frame is not None:
        _draw_map_frame(ax, scenario)
    plt.colorbar(
        mesh,
        ax=ax,
        fraction=0.046,
        pad=0.04,
        label=f"{truth.label} at z = {scenario.agent.start[2]:g} m, t = {until:.0f} s (g/m³)",
    )


def _draw_compass(ax: plt.Axes, phi_deg: float) -> None:
    """A north arrow and the wind as people say it, above the map's top-right corner (outside
    the map, so they hide nothing): an arrow pointing where the wind blows (downwind), and its
    compass bearing (where it comes from, clockwise from north; dcee's y axis is north)."""
    from dcee.models.compass import wind_from_words

    ax.annotate(
        "N", xy=(0.985, 1.115), xytext=(0.985, 1.02), xycoords="axes fraction",
        ha="center", va="bottom", fontsize=7, fontweight="bold", annotation_clip=False,
        arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.0, "shrinkA": 0, "shrinkB": 0},
    )  # fmt: skip
    phi = np.radians(phi_deg)
    down = -np.array([np.cos(phi), np.sin(phi)])  # the plume goes this way
    centre, half = np.array([0.9, 1.065]), 0.04
    ax.annotate(
        "", xy=tuple(centre + half * down), xytext=tuple(centre - half * down),
        xycoords="axes fraction", annotation_clip=False,
        arrowprops={"arrowstyle": "-|>", "color": "tab:blue", "lw": 1.4, "shrinkA": 0,
                    "shrinkB": 0},
    )  # fmt: skip
    ax.text(
        0.84, 1.065, wind_from_words(phi_deg), transform=ax.transAxes, ha="right",
        va="center", fontsize=7, color="tab:blue",
    )  # fmt: skip


def _draw_map_frame(ax: plt.Axes, scenario: Scenario) -> None:
    """A site in geographic coordinates: a scale bar in the map's lower-right corner and the
    local frame's origin in degrees under the map."""
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    width = scenario.volume.high[0] - scenario.volume.low[0]
    nice = [1, 2, 5, 10, 20, 25, 50, 100, 200, 250, 500, 1000, 2000, 5000, 10000]
    length = max((n for n in nice if n <= width / 4), default=nice[0])
    ax.add_artist(
        AnchoredSizeBar(
            ax.transData, length, f"{length:g} m", "lower right", pad=0.4, frameon=True,
            size_vertical=width / 200, fontproperties={"size": 7},
        )
    )  # fmt: skip
    frame = scenario.world.frame
    assert frame is not None
    lon, lat = frame.local_frame().to_geo(np.array([0.0]), np.array([0.0]))
    ax.set_xlabel(
        f"x (m east; (0, 0) = {abs(lat[0]):.6f}° {'N' if lat[0] >= 0 else 'S'}, "
        f"{abs(lon[0]):.6f}° {'E' if lon[0] >= 0 else 'W'}, transverse Mercator about the site)",
        fontsize=8,
    )
    ax.set_ylabel("y (m north)")


def _draw_rmse(ax: plt.Axes, result: EpisodeResult, scenario: Scenario, until: float) -> None:
    recs = [r for r in result.records if r["time"] <= until + 1e-9]
    t = np.array([r["time"] for r in recs])
    ax.semilogy(t, [r["rmse"] for r in recs], color="tab:red", label="RMSE about true source")
    ax.semilogy(
        t, [r["spread"] for r in recs], color="tab:blue", ls="--", label="posterior spread √tr P"
    )
    ax.semilogy(
        t, [r["mean_error"] for r in recs], color="0.4", lw=0.8, label="error of posterior mean"
    )
    for level in (scenario.search.acquired_rmse, 1.0, 0.5):
        ax.axhline(level, color="0.7", lw=0.6, ls=":")
    ax.set_xlim(0, scenario.search.budget)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("m")
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3, which="both")


ROBOT_COLOURS = ("tab:red", "tab:purple", "tab:orange", "tab:brown", "tab:pink", "tab:olive")
"""A team's robots by index, on the map and in the altitude panel."""


def _robot_colour(k: int) -> str:
    return ROBOT_COLOURS[int(k) % len(ROBOT_COLOURS)]


def _shows_altitude(result: EpisodeResult, scenario: Scenario) -> bool:
    """A search in three dimensions: the agent changed altitude or the source height was
    estimated."""
    heights = {round(float(r["z"]), 6) for r in result.records}
    return len(heights) > 1 or "z" in scenario.unknown_names


def _draw_altitude(ax: plt.Axes, result: EpisodeResult, scenario: Scenario, until: float) -> None:
    """The agent's altitude over time, the estimated source height (mean ± sd) and the true
    one."""
    recs = [r for r in result.records if r["time"] <= until + 1e-9]
    robot = np.array([r.get("robot", 0) for r in recs])
    robots = np.unique(robot)
    t_all = np.array([r["time"] for r in recs])
    z_all = np.array([r["z"] for r in recs])
    # the sensor's height: a UAV's altitude, or a ground robot's fixed sensor; one trace a
    # robot (a team's records interleave its robots at each time)
    for k in robots:
        on = robot == k
        label = "sensor" if len(robots) == 1 else f"robot {k} sensor"
        ax.step(t_all[on], z_all[on], where="post", color=_robot_colour(k), lw=1.0, label=label)
    # the team shares one belief: its estimate once per time, from the first robot's records
    recs = [r for r, k in zip(recs, robot, strict=True) if k == robots[0]]
    t = np.array([r["time"] for r in recs])
    mean = np.array([r["mean_z"] for r in recs])
    sd = np.sqrt(np.maximum([r["cov_zz"] for r in recs], 0.0))
    ax.plot(t, mean, color="tab:blue", lw=1.0, label="source height, estimate ± sd")
    ax.fill_between(t, mean - sd, mean + sd, color="tab:blue", alpha=0.2, lw=0)
    ax.axhline(scenario.truth.z, color="k", lw=0.8, ls="--", label="true source height")
    ax.set_xlim(0, scenario.search.budget)
    ax.set_ylim(scenario.volume.low[2], scenario.volume.high[2])
    ax.set_xlabel("time (s)")
    ax.set_ylabel("height (m)")
    ax.legend(fontsize=7, loc="upper right", ncol=3)
    ax.grid(alpha=0.3)


def draw_search_figure(result: EpisodeResult, scenario: Scenario, truth: TruthModel) -> Figure:
    """The summary figure of one search (map with trajectory and particles, RMSE over time,
    and in three dimensions the altitudes over time); the caller saves or renders it and closes
    it."""
    s = result.summary
    if _shows_altitude(result, scenario):
        fig = plt.figure(figsize=(13, 6.4))
        grid = fig.add_gridspec(3, 2, width_ratios=[1.15, 1])
        ax_map = fig.add_subplot(grid[:, 0])
        ax_rmse = fig.add_subplot(grid[:2, 1])
        ax_z = fig.add_subplot(grid[2, 1])
        _draw_altitude(ax_z, result, scenario, scenario.search.budget)
    else:
        fig, (ax_map, ax_rmse) = plt.subplots(1, 2, figsize=(13, 6.4), width_ratios=[1.15, 1])
    idx = np.random.default_rng(0).choice(
        len(result.final_weights),
        size=min(3000, len(result.final_weights)),
        p=result.final_weights,
    )
    _draw_map(ax_map, result, scenario, truth, result.records[-1]["time"], result.final_theta[idx])
    ax_map.legend(
        fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=4, markerscale=0.8
    )
    _draw_rmse(ax_rmse, result, scenario, scenario.search.budget)
    fig.suptitle(
        f"{s['scenario']} · {s['strategy']} · seed {s['seed']} · {truth.name} truth"
        f" · final RMSE {s['final_rmse']:.2f} m"
        f" · source {'acquired' if s['source_acquired'] else 'not acquired'}"
        + (
            f" · {s['true_sources']} releases, OSPA {s['final_ospa']:.2f} m"
            if s.get("true_sources", 1) > 1 or "estimated_count" in s
            else ""
        ),
        fontsize=11,
    )
    # room below the map for its legend (placed under the axes), also when the figure is shown
    # or saved without bbox_inches="tight"
    fig.tight_layout(rect=(0, 0.07, 1, 0.95))
    return fig


def render_search(
    result: EpisodeResult, scenario: Scenario, truth: TruthModel, dpi: int = 80
) -> np.ndarray:
    """The summary figure of one search as an (H, W, 3) uint8 RGB image (environments'
    ``render``)."""
    from io import BytesIO

    from PIL import Image

    fig = draw_search_figure(result, scenario, truth)
    buffer = BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    buffer.seek(0)
    return np.asarray(Image.open(buffer).convert("RGB"))


def search_figure(
    result: EpisodeResult, scenario: Scenario, truth: TruthModel, path: str | Path
) -> None:
    """Write the summary figure of one search (PNG) to ``path``."""
    fig = draw_search_figure(result, scenario, truth)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def search_animation(
    result: EpisodeResult, scenario: Scenario, truth: TruthModel, path: str | Path
) -> None:
    """Write an animated GIF of the search (one frame per particle snapshot)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    fig = plt.figure(figsize=(11, 4.8))

    def frame(k: int) -> None:
        fig.clear()
        a1 = fig.add_subplot(1, 2, 1)
        a2 = fig.add_subplot(1, 2, 2)
        t, parts = result.snapshots[k]
        _draw_map(a1, result, scenario, truth, t, parts)
        _draw_rmse(a2, result, scenario, t)

    anim = FuncAnimation(fig, frame, frames=len(result.snapshots))
    anim.save(str(path), writer=PillowWriter(fps=4), dpi=70)
    plt.close(fig)
