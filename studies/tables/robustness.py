"""Files from others read without trust: the fuzz benchmark of every reader (issue 80)."""

from __future__ import annotations

import json

from studies.tables.common import RESULTS, table

FOLDER = RESULTS / "fuzz"


def fuzz_readers_table() -> str:
    """Per format: the corrupted cases run, how many were read and refused (one line), and how
    many failed (another exception, several lines, no answer in 30 s)."""
    doc = json.loads((FOLDER / "readers.json").read_text(encoding="utf-8"))
    machine = doc["machine"]
    commit = str(doc["code_version"].get("commit", ""))[:9]
    rows = [
        [
            r["format"],
            str(r["cases"]),
            str(r["read"]),
            str(r["refused"]),
            str(len(r["failures"])),
            f"{r['seconds']:.0f}",
        ]
        for r in doc["formats"]
    ]
    rows.append(
        [
            f"all ({machine['processor'] or machine['machine']}, code {commit})",
            str(sum(r["cases"] for r in doc["formats"])),
            str(sum(r["read"] for r in doc["formats"])),
            str(sum(r["refused"] for r in doc["formats"])),
            str(sum(len(r["failures"]) for r in doc["formats"])),
            f"{sum(r['seconds'] for r in doc['formats']):.0f}",
        ]
    )
    return table(["format", "cases", "read", "refused (one line)", "failed", "seconds"], rows)


SOAK_BOUNDS = {"rss_mb": 200.0, "decision": 2.0, "latency": 2.0}
"""Stated before the soak was run (2026-12-04): resident memory at the end at most 200 MB above
its value after the first 100 readings; the mean decision time and the mean latency over the
last 100 readings at most twice their mean over readings 100-200 (the first 100 warm up the
compiled kernels and the caches)."""


def _soak() -> dict:
    return json.loads((RESULTS / "soak" / "soak.json").read_text(encoding="utf-8"))


def _window(samples: list[dict], lo: int, hi: int, key: str) -> float | None:
    vals = [s[key] for s in samples if lo <= s["readings"] < hi and s.get(key) is not None]
    return sum(vals) / len(vals) if vals else None


def soak_table() -> str:
    """Memory, decision time and latency early in the soak and at its end, against the bounds
    (:data:`SOAK_BOUNDS`)."""
    doc = _soak()
    samples = doc["soak"]["samples"]
    last = max(s["readings"] for s in samples)
    rows = []
    for key, label, unit, scale, bound in (
        ("rss_mb", "resident memory", "MB", 1.0, ("+", SOAK_BOUNDS["rss_mb"])),
        ("decision_s_last20", "decision time (mean of the last 20)", "ms", 1e3,
         ("x", SOAK_BOUNDS["decision"])),
        ("latency_s_mean", "latency, pose to goal (mean)", "ms", 1e3,
         ("x", SOAK_BOUNDS["latency"])),
    ):  # fmt: skip
        early = _window(samples, 100, 200, key)
        late = _window(samples, last - 100, last + 1, key)
        if early is None or late is None:
            continue
        if bound is None:
            verdict = "—"
        elif bound[0] == "+":
            verdict = ("within" if late - early <= bound[1] else "BEYOND") + f" +{bound[1]:g} MB"
        else:
            verdict = ("within" if late <= bound[1] * early else "BEYOND") + f" {bound[1]:g}×"
        rows.append([label, f"{early * scale:.1f} {unit}", f"{late * scale:.1f} {unit}", verdict])
    head = ["", "readings 100-200", f"last 100 (of {last})", "bound"]
    return table(head, rows)


def soak_faults_table() -> str:
    """Each injected fault: the readings, dropped poses, clock jumps and unwritten checkpoints
    before and after it, and whether the search went on."""
    doc = _soak()
    rows = []
    for f in doc["soak"]["faults"]:
        b, a = f["before"], f["after"]
        dropped = sum(a["rejected"].values()) - sum(b["rejected"].values())
        rows.append(
            [
                f["fault"],
                f"{b['sim_time']:.0f}",
                f"{b['readings']} → {a['readings']}",
                str(dropped),
                str(a["clock_jumps"] - b["clock_jumps"]),
                str(a["checkpoint_failures"] - b["checkpoint_failures"]),
                str(a["callback_errors"] - b["callback_errors"]),
            ]
        )
    kill = doc["kill"]
    rows.append(
        [
            "SIGKILL, started again on the checkpoint",
            f"{kill['time_in_checkpoint_at_kill_s']:.0f}",
            f"{kill['readings_in_checkpoint_at_kill']} → {kill['second_readings_written']}",
            "—",
            "—",
            "—",
            "history kept" if kill["history_before_kill_kept"] else "HISTORY LOST",
        ]
    )
    head = ["fault", "at s (simulated)", "readings before → after", "messages dropped",
            "clock jumps", "checkpoints not written", "callback errors"]  # fmt: skip
    return table(head, rows)


def soak_run_table() -> str:
    """The run itself: simulated hours, readings, wall time, machine and code."""
    doc = _soak()
    s = doc["soak"]
    machine = doc["machine"]
    return table(
        ["scenario, planner", "particles", "simulated", "readings", "wall", "machine", "code"],
        [
            [
                f"{doc['scenario']}, {doc['strategy']}",
                f"{doc['particles']:,}",
                f"{doc['hours']:g} h",
                str(s["readings"]),
                f"{s['wall_seconds'] / 60:.1f} min",
                f"{machine['processor'] or machine['machine']}, {machine['cpus']} CPUs",
                str(doc["code_version"].get("commit", ""))[:9],
            ]
        ],
    )


def soak_worst_table() -> str:
    """The worst latency from a pose to its goal in each quarter of the soak (by readings), and
    how many of the 2 s samples held one over 100 ms: the rare resampling steps, whose
    rejuvenation weighs every particle against every past reading."""
    samples = _soak()["soak"]["samples"]
    last = max(s["readings"] for s in samples)
    rows = []
    for q in range(4):
        lo, hi = q * last // 4, (q + 1) * last // 4 + (1 if q == 3 else 0)
        part = [s for s in samples if lo <= s["readings"] < hi]
        worst = [s["latency_s_max"] for s in part if s.get("latency_s_max") is not None]
        if not worst:
            continue
        gcs = [s["full_gc_s_max"] for s in part if s.get("full_gc_s_max") is not None]
        slow = [s for s in part if (s.get("latency_s_max") or 0) > 0.1]
        with_gc = sum(1 for s in slow if (s.get("full_gc_s_max") or 0) > 0.05)
        rows.append(
            [
                f"{lo}-{hi - (1 if q == 3 else 0)}",
                f"{max(worst) * 1e3:.0f} ms",
                f"{len(slow)} of {len(worst)}",
                f"{max(gcs) * 1e3:.0f} ms ({len(gcs)})" if gcs else "none",
                f"{with_gc} of {len(slow)}",
            ]
        )
    head = ["readings", "worst latency", "samples with one over 100 ms",
            "longest full collection (count)", "slow ones with a collection > 50 ms"]  # fmt: skip
    return table(head, rows)
