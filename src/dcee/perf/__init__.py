"""Performance workloads (``dcee perf``) and the side-by-side comparison with Stone Soup."""

from dcee.perf.workloads import Timing, run_workloads

__all__ = ["Timing", "run_workloads"]
