"""A day on a robot, compressed (issue 80): the ROS 2 node against the simulated robot over ROS 2
topics for hours of simulated time, its resident memory, decision time and the latency from
the pose that completes a reading to the published goal sampled throughout, and faults
injected while it runs:

* the robot's clock jumps back 300 s (``/clock`` and every stamp; half its reading in a run
  shorter than 10 min);
* for 60 s every reading arrives twice and a pose 0.5 s late follows every pose;
* a burst of 1,000 readings within one second;
* the checkpoint's disk full (ENOSPC) for 120 s, then read-only (EROFS) for 120 s;
* afterwards, in two child processes: the node killed with SIGKILL mid-search, and started
  again on its checkpoint.

Run with the ROS 2 venv in place (``bash scripts/setup-ros.sh``; from another interpreter the
script runs itself again in ``.venv-ros``)::

    python studies/soak_node.py --hours 8 --particles 20000 --json docs/results/soak/soak.json

The search never stops on its own (``search.stop_spread = 0``): one search reads for the whole
run, so the estimator's history grows as on the longest mission.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
SCENARIO, STRATEGY = "lab:upwind", "infotaxis"


def _rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


class Soak:
    """Samples the node and injects the faults (module doc) from a thread of its own."""

    def __init__(self, budget: float, interval: float) -> None:
        self.budget, self.interval = budget, interval
        self.samples: list[dict[str, Any]] = []
        self.faults: list[dict[str, Any]] = []
        self.stop = threading.Event()
        self.gc_pauses: list[tuple[float, float]] = []  # (wall end, seconds) of full collections
        self._gc_started = 0.0
        import gc

        gc.callbacks.append(self._gc)

    def _gc(self, phase: str, info: dict) -> None:
        """Times Python's full (generation 2) garbage collections: a suspect of the rare long
        waits for a goal (docs/guide/robot.md)."""
        if info.get("generation") != 2:
            return
        if phase == "start":
            self._gc_started = time.perf_counter()
        else:
            self.gc_pauses.append((time.perf_counter(), time.perf_counter() - self._gc_started))

    def observe(self, search: Any, sim: Any, context: Any) -> None:
        import rclpy
        from nav_msgs.msg import Odometry
        from std_msgs.msg import Float32

        from dcee.ros.parameters import RELIABLE

        self.search, self.sim = search, sim
        self.node = rclpy.create_node("dcee_faults", context=context)
        self.conc_pub = self.node.create_publisher(Float32, "concentration", RELIABLE)
        self.odom_pub = self.node.create_publisher(Odometry, "odom", RELIABLE)
        threading.Thread(target=self._run, daemon=True).start()

    # --- faults ---------------------------------------------------------------------------------

    def _state(self) -> dict[str, Any]:
        s = self.search
        cycle = s.cycle
        return {
            "sim_time": float(self.sim.robot.time),
            "readings": len(cycle.records) if cycle is not None else 0,
            "rejected": dict(cycle.rejected) if cycle is not None else {},
            "clock_jumps": cycle.clock_jumps if cycle is not None else 0,
            "checkpoint_failures": s.checkpoint_failures,
            "callback_errors": s.callback_errors,
        }

    def _fault(self, name: str, action: Any, seconds: float = 0.0) -> None:
        before = self._state()
        action_end = action()
        if seconds:
            end = self.sim.robot.time + seconds
            while self.sim.robot.time < end and not self.stop.is_set():
                if callable(action_end):
                    action_end()
                time.sleep(0.02)
        self.faults.append({"fault": name, "before": before, "after": self._state()})

    def _jump(self) -> None:
        # 300 s back (half the clock where less has passed: ROS time cannot go below zero)
        self.sim.clock_offset -= min(300.0, 0.5 * (self.sim.robot.time + self.sim.clock_offset))

    def _late_and_twice(self) -> Any:
        from nav_msgs.msg import Odometry
        from std_msgs.msg import Float32

        from dcee.ros.sim_node import stamp_of

        def each() -> None:
            r = self.sim.robot
            self.conc_pub.publish(Float32(data=r.sample()))  # the reading again
            s = r.odometry()
            late = Odometry()
            late.header.stamp = stamp_of(r.time + self.sim.clock_offset - 0.5)
            late.header.frame_id = "map"
            late.pose.pose.position.x, late.pose.pose.position.y = s.x, s.y
            late.pose.pose.orientation.w = 1.0
            self.odom_pub.publish(late)

        return each

    def _burst(self) -> None:
        from std_msgs.msg import Float32

        r = self.sim.robot
        for _ in range(1000):
            self.conc_pub.publish(Float32(data=r.sample()))
            time.sleep(0.0009)

    def _disk(self, errno_text: str) -> Any:
        import dcee.searcher
        from dcee.errors import DceeInputError

        def refuse(searcher: Any, path: Any) -> Path:
            raise DceeInputError("path", f"cannot write checkpoint {path}: {errno_text}")

        dcee.searcher.Searcher.save = refuse

    def _disk_back(self) -> None:
        import dcee.searcher

        dcee.searcher.Searcher.save = self._real_save

    # --- the sampler ----------------------------------------------------------------------------

    def _run(self) -> None:
        import dcee.searcher

        self._real_save = dcee.searcher.Searcher.save
        plan = [
            (0.20, "clock jumps back (then 60 s)", self._jump, 60.0),
            (0.35, "every reading twice and a late pose after every pose, 60 s",
             self._late_and_twice, 60.0),
            (0.50, "a burst of 1,000 readings in one second (then 60 s)", self._burst, 60.0),
            (0.60, "checkpoint disk full (ENOSPC), 120 s",
             lambda: self._disk("[Errno 28] No space left on device"), 120.0),
            (0.60, "disk back", self._disk_back, 0.0),
            (0.75, "checkpoint disk read-only (EROFS), 120 s",
             lambda: self._disk("[Errno 30] Read-only file system"), 120.0),
            (0.75, "disk back", self._disk_back, 0.0),
        ]  # fmt: skip
        last_pose = -1e300
        seen_gc = 0
        started = time.monotonic()
        while not self.stop.is_set():
            t = self.sim.robot.time
            while plan and t >= plan[0][0] * self.budget:
                _, name, action, seconds = plan.pop(0)
                self._fault(name, action, seconds)
            cycle = self.search.cycle
            records = cycle.records if cycle is not None else []
            try:
                latency = list(self.search.step_latency)
            except RuntimeError:  # changed by the executor's thread while copied: next time
                latency = []
            fresh = [w for t_pose, w in latency if t_pose > last_pose]
            if latency:
                last_pose = max(last_pose, latency[-1][0])
            pauses = [p for _, p in self.gc_pauses[seen_gc:]]
            seen_gc = len(self.gc_pauses)
            decisions = [r.get("decision_seconds") for r in records[-20:]]
            decisions = [d for d in decisions if d is not None]
            self.samples.append(
                {
                    "wall": round(time.monotonic() - started, 2),
                    "sim_time": round(float(t), 1),
                    "readings": len(records),
                    "rss_mb": round(_rss_mb(), 1),
                    "decision_s_last20": round(sum(decisions) / len(decisions), 4)
                    if decisions
                    else None,
                    "latency_s_max": round(max(fresh), 4) if fresh else None,
                    "latency_s_mean": round(sum(fresh) / len(fresh), 4) if fresh else None,
                    "full_gc_s_max": round(max(pauses), 4) if pauses else None,
                }
            )
            time.sleep(self.interval)


def soak(args: argparse.Namespace) -> dict[str, Any]:
    from dcee.ros.demo import run_demo
    from dcee.searcher import Searcher

    budget = args.hours * 3600.0
    checkpoint = Path(args.scratch) / "soak.ckpt"
    checkpoint.unlink(missing_ok=True)
    watcher = Soak(budget, args.sample)
    summary = run_demo(
        SCENARIO,
        STRATEGY,
        seed=0,
        particles=args.particles,
        budget=budget,
        speedup=args.speedup,
        timeout=args.timeout,
        overrides={"search.stop_spread": 0.0},
        checkpoint=checkpoint,
        observer=watcher.observe,
    )
    watcher.stop.set()
    watcher._disk_back()
    saved = Searcher.load(checkpoint)
    return {
        "readings": len(summary["records"]),
        "finish_reason": summary["finish_reason"],
        "wall_seconds": summary["wall_seconds"],
        "checkpoint_readings_at_end": int(saved.filter.n_readings),
        "faults": watcher.faults,
        "samples": watcher.samples,
    }


def _written(checkpoint: Path) -> Any:
    from dcee.searcher import Searcher

    try:
        return Searcher.load(checkpoint)
    except Exception:  # not there yet
        return None


def _wait_for(checkpoint: Path, readings: int, process: Any, timeout: float) -> Any:
    """The checkpoint once it holds ``readings`` readings (or the process ended)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and process.poll() is None:
        searcher = _written(checkpoint)
        if searcher is not None and searcher.filter.n_readings >= readings:
            return searcher
        time.sleep(0.2)
    return _written(checkpoint)


def kill_and_resume(args: argparse.Namespace) -> dict[str, Any]:
    """A child process searches with a checkpoint and is killed with SIGKILL once the file
    holds ``--kill-after`` readings; a second child, with the same parameters (what a robot's
    supervisor restarts), resumes from the file and is stopped once it has written five more.
    Its history must begin with every reading the first one wrote."""
    checkpoint = Path(args.scratch) / "killed.ckpt"
    checkpoint.unlink(missing_ok=True)
    child = [sys.executable, __file__, "--child", "--checkpoint", str(checkpoint),
             "--particles", str(args.particles), "--speedup", str(args.speedup),
             "--budget", "100000"]  # fmt: skip
    first = subprocess.Popen(child, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _wait_for(checkpoint, args.kill_after, first, args.timeout)
    os.kill(first.pid, signal.SIGKILL)
    first.wait()
    at_kill = _written(checkpoint)
    pos0, z0, _ = at_kill.filter.history()
    second = subprocess.Popen(child, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    later = _wait_for(checkpoint, at_kill.filter.n_readings + 5, second, args.timeout)
    second.terminate()
    _, err = second.communicate(timeout=60)
    pos1, z1, _ = later.filter.history()
    kept = len(z1) >= len(z0) and np.array_equal(z1[: len(z0)], z0)
    kept = kept and np.array_equal(pos1[: len(pos0)], pos0)
    resumed = "resumed the search from" in err.decode(errors="replace")
    return {
        "killed_with": "SIGKILL",
        "first_exit_code": first.returncode,
        "readings_in_checkpoint_at_kill": int(at_kill.filter.n_readings),
        "time_in_checkpoint_at_kill_s": round(float(at_kill.time), 2),
        "second_logged_resumed": resumed,
        "second_readings_written": int(later.filter.n_readings),
        "second_time_s": round(float(later.time), 2),
        "history_before_kill_kept": bool(kept),
    }


def child(args: argparse.Namespace) -> None:
    from dcee.ros.demo import run_demo

    summary = run_demo(
        SCENARIO,
        STRATEGY,
        seed=0,
        particles=args.particles,
        budget=args.budget,
        speedup=args.speedup,
        timeout=args.timeout,
        overrides={"search.stop_spread": 0.0},
        checkpoint=Path(args.checkpoint),
    )
    recs = summary["records"]
    if args.out:
        Path(args.out).write_text(
            json.dumps(
                {
                    "readings": len(recs),
                    "first_step": recs[0]["step"] if recs else None,
                    "first_time": recs[0]["time"] if recs else None,
                }
            )
        )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--hours", type=float, default=3.0, help="simulated hours of the soak")
    ap.add_argument("--particles", type=int, default=5000)
    ap.add_argument("--speedup", type=float, default=100.0)
    ap.add_argument("--sample", type=float, default=1.0, help="wall s between samples")
    ap.add_argument("--timeout", type=float, default=7200.0)
    ap.add_argument("--kill-after", type=int, default=20, help="readings before SIGKILL")
    ap.add_argument("--scratch", default="/tmp")
    ap.add_argument("--json")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--checkpoint", help=argparse.SUPPRESS)
    ap.add_argument("--budget", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    try:
        import rclpy  # noqa: F401
    except ImportError:  # run from the main venv (a recipe step): the ROS 2 venv runs it
        ros = ROOT / ".venv-ros" / "bin" / "python"
        if not ros.exists():
            print("soak_node: needs the ROS 2 venv: bash scripts/setup-ros.sh", file=sys.stderr)
            return 2
        os.execv(str(ros), [str(ros), __file__, *(sys.argv[1:] if argv is None else argv)])
    if args.child:
        child(args)
        return 0
    from dcee.perf.machine import machine_record
    from dcee.provenance import code_version

    doc = {
        "code_version": code_version(),
        "machine": machine_record(),
        "scenario": SCENARIO,
        "strategy": STRATEGY,
        "particles": args.particles,
        "hours": args.hours,
        "speedup": args.speedup,
        "soak": soak(args),
        "kill": kill_and_resume(args),
    }
    print(json.dumps({k: v for k, v in doc["soak"].items() if k != "samples"}, indent=1))
    print(json.dumps(doc["kill"], indent=1))
    if args.json:
        out = Path(args.json)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
