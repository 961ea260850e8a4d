"""
# A planner of your own

A planner is a small class registered by name; nothing else in dcee changes. Hypothesis-based
planners only define a *loss* per hypothesised reading; the expectation over readings (sampled
or stratified), the multistage search and the compiled kernels are shared.

This one, "greedy spread", charges the expected posterior variance of the source location and
nothing else (pure exploration). We run it and MPC (pure exploitation) on the same seed, so both
see the same truth noise, and compare their RMSE over time.
"""

import matplotlib.pyplot as plt

from dcee.planning import HypothesisPlanner, register, unregister
from dcee.runs import run_episode
from dcee.scenarios import load_scenario


@register("greedy-spread")
class GreedySpreadPlanner(HypothesisPlanner):
    """Expected posterior variance of the source location after the next reading."""

    summary = "expected location variance after the next reading (pure exploration)"
    needs_kl = False  # the loss needs the predicted moments, not the KL divergence

    def loss(self, final_positions, stats, belief):
        return stats.trace_cov  # (moves, hypotheses) expected tr P'


scenario = load_scenario("paper:1").with_overrides(
    **{"search.particles": 2000, "search.hypotheses": 20, "search.budget": 300.0}
)
results = {name: run_episode(scenario, name, seed=0) for name in ("greedy-spread", "mpc")}
for name, res in results.items():
    s = res.summary
    print(
        f"{name:14s} final RMSE {s['final_rmse']:.2f} m, time to RMSE < 1 m: {s['time_to_rmse_1m']}"
    )

# %%
# RMSE of the particles about the true source over time, same seed for both.

fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
for name, res in results.items():
    ax.semilogy([r["time"] for r in res.records], [r["rmse"] for r in res.records], label=name)
ax.axhline(1.0, color="0.6", ls=":")
ax.set(xlabel="time (s)", ylabel="RMSE (m)")
ax.legend()
plt.show()
unregister("greedy-spread")  # the registry is process-wide
