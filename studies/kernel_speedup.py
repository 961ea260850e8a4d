"""The predicted-posterior kernel before and after a change, timed in alternation in one process
(issue 46): the kernel module of an earlier commit (read with ``git show``) against today's, on
the same synthetic position terms, for the sums each planner reads, with the largest difference
of their outputs. Writes JSON (with the machine and the load beside the run,
dcee.perf.machine) that docs/performance.md's table is generated from.

    .venv/bin/python studies/kernel_speedup.py [--before f52a5b6] \\
        [--json docs/results/perf/kernel-speedup.json]
"""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dcee.io import write_json
from dcee.models.sensor import Sensor
from dcee.perf.machine import LoadMonitor, load_warning, machine_record
from dcee.planning.predicted_kernels import predicted_posterior_stats

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from tests.helpers import _terms_from_concentrations  # the kernel tests' position terms

ROOT = Path(__file__).resolve().parent.parent
KERNEL = "src/dcee/planning/predicted_kernels.py"
REPEATS = 15

# (name, sensor, stages, hypotheses per sequence, sequences, particles, moments, kl, precision
# of today's side: the planners' option, "single" for the float32 weights)
WORKLOADS = (
    ("one stage, dcee (moments)", "default", 1, 41, 8, 20_000, True, False, "double"),
    ("one stage, dcee-cl (moments and KL)", "default", 1, 41, 8, 20_000, True, True, "double"),
    ("one stage, infotaxis (KL)", "default", 1, 41, 8, 20_000, False, True, "double"),
    ("three stages, tree search (moments and KL)", "default", 3, 11, 20, 10_000, True, True,
     "double"),
    ("one stage, paper-exact model (no outlier: unchanged)", "paper", 1, 41, 8, 20_000, True, True,
     "double"),
    ("one stage, dcee-cl, `precision=single`", "default", 1, 41, 8, 20_000, True, True, "single"),
    ("one stage, infotaxis, `precision=single`", "default", 1, 41, 8, 20_000, False, True,
     "single"),
)  # fmt: skip


# the kernel module and the planning modules it imports from, read from the earlier commit
# together (a module that changed beside the kernel is taken as it was then)
KERNEL_MODULES = ("predicted_kernels", "predicted_single", "block_sums", "reading_terms")


def _kernel_at(commit: str):
    """predicted_posterior_stats of ``commit``'s kernel module (imported from a copy, with the
    planning modules it imports from taken from the same commit)."""
    folder = Path(tempfile.mkdtemp())
    package = f"kernels_{commit}"
    (folder / package).mkdir()
    (folder / package / "__init__.py").write_text("")
    for name in KERNEL_MODULES:
        try:
            source = subprocess.run(
                ["git", "-C", str(ROOT), "show", f"{commit}:src/dcee/planning/{name}.py"],
                check=True,
                capture_output=True,
                text=True,
            ).stdout
        except subprocess.CalledProcessError:
            if name == "predicted_kernels":
                raise
            continue  # not there yet at that commit: nothing imports it
        for other in KERNEL_MODULES:
            source = source.replace(f"dcee.planning.{other} ", f"{package}.{other} ")
        (folder / package / f"{name}.py").write_text(source.replace("cache=True", "cache=False"))
    sys.path.insert(0, str(folder))
    module = importlib.import_module(f"{package}.predicted_kernels")
    return module.predicted_posterior_stats


def _workload(sensor_kind, stages, hypotheses, sequences, particles, seed=0):
    rng = np.random.default_rng(seed)
    sensor = Sensor() if sensor_kind == "default" else Sensor.paper_exact()
    positions = 12
    conc = rng.lognormal(-6.0, 2.5, size=(positions, particles))
    source = rng.uniform(0.0, 50.0, size=(particles, 3))
    w = rng.random(particles)
    w[rng.random(particles) < 0.3] = 0.0  # resampled beliefs hold dead copies
    w /= w.sum()
    seqs = rng.integers(0, positions, size=(sequences, stages))
    task_pos = np.ascontiguousarray(np.repeat(seqs, hypotheses, axis=0), dtype=np.int64)
    s = len(task_pos)
    z = sensor.simulate_from(
        conc[task_pos, rng.integers(0, particles, (s, 1))], sensor.draw_noise(rng, (s, stages))
    )
    z[rng.random((s, stages)) < 0.3] = 0.0  # non-detections among the hypotheses
    terms = _terms_from_concentrations(conc, None, sensor)
    return sensor, terms, source, w, task_pos, sensor.transformed_readings(z)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="f52a5b6", help="the commit to compare with")
    ap.add_argument("--json", type=Path, help="write the results here")
    args = ap.parse_args(argv)
    try:
        before = _kernel_at(args.before)
    except subprocess.CalledProcessError as exc:
        first = (exc.stderr or "").strip().splitlines()[:1] or ["git show failed"]
        print(f"kernel_speedup: error: --before {args.before}: {first[0]}", file=sys.stderr)
        return 2
    rows = []
    with LoadMonitor() as load:
        for name, kind, stages, hyp, seqs, n, moments, kl, precision in WORKLOADS:
            sensor, terms, source, w, task_pos, readings = _workload(kind, stages, hyp, seqs, n)
            s = len(task_pos)

            def run(kernel, sensor=sensor, terms=terms, source=source, w=w, task_pos=task_pos,
                    readings=readings, s=s, moments=moments, kl=kl,
                    precision=precision):  # fmt: skip
                out = [np.empty(s), np.empty((s, 3)), np.empty(s), np.empty(s)]
                today = {} if kernel is before else {"precision": precision}  # the old had none
                kernel(*terms, source, w, w @ source, task_pos, *readings, sensor.params, *out,
                       want_moments=moments, want_kl=kl, **today)  # fmt: skip
                return out

            old, new = run(before), run(predicted_posterior_stats)  # also compiles both
            wanted = [0] + ([1, 2] if moments else []) + ([3] if kl else [])
            diff = max(float(np.max(np.abs(old[k] - new[k]))) for k in wanted)
            times: dict[str, list[float]] = {"before": [], "after": []}
            for _ in range(REPEATS):  # in alternation: both see the same load
                for tag, kernel in (("before", before), ("after", predicted_posterior_stats)):
                    t0 = time.perf_counter()
                    run(kernel)
                    times[tag].append(1e3 * (time.perf_counter() - t0))
            b, a = float(np.median(times["before"])), float(np.median(times["after"]))
            rows.append(
                {
                    "workload": name,
                    "tasks": s,
                    "particles": n,
                    "precision": precision,
                    "before_ms": b,
                    "after_ms": a,
                    "speedup": b / a,
                    "max_abs_difference": diff,
                }
            )
            print(f"{name}: {b:.2f} ms -> {a:.2f} ms ({b / a:.2f}x), outputs within {diff:.1e}")
    if warning := load_warning(load.record()):
        print(warning)
    if args.json:
        record = {"machine": machine_record(), "load": load.record(), "before": args.before}
        write_json(args.json, {**record, "repeats": REPEATS, "workloads": rows})
    return 0


if __name__ == "__main__":
    sys.exit(main())
