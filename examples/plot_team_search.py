"""
# Several robots, one belief

`agent.count` robots (`dcee run --agents K`) share one particle filter: every robot's reading
updates the same belief, and the next moves are planned jointly by sequential greedy planning,
each robot valuing what its reading would add to the readings of the robots before it. Here one
and three robots with infotaxis on paper:1, the same seed, 3,000 particles and a 300 s budget
(small, so that the documentation builds quickly): the RMSE over time, and the three robots'
trajectories.
"""

import matplotlib.pyplot as plt

from dcee.analysis.figures import draw_search_figure
from dcee.runs import run_episode
from dcee.scenarios import load_scenario
from dcee.simulation import make_truth

base = load_scenario("paper:1").with_overrides(**{"search.particles": 3000, "search.budget": 300.0})
results = {}
for robots in (1, 3):
    scenario = base.with_overrides(**{"agent.count": robots})
    results[robots] = (scenario, run_episode(scenario, "infotaxis", seed=0))
    s = results[robots][1].summary
    print(
        f"{robots} robot(s): final RMSE {s['final_rmse']:.2f} m, time to RMSE < 1 m "
        f"{s['time_to_rmse_1m']} s, {s['readings']} readings"
    )

fig, ax = plt.subplots(figsize=(7, 3.6))
for robots, (_, result) in results.items():
    last = {}
    for r in result.records:  # the belief after every robot's reading of a step
        last[r["time"]] = r["rmse"]
    ax.semilogy(list(last), list(last.values()), label=f"{robots} robot(s)")
ax.set_xlabel("time (s)")
ax.set_ylabel("RMSE about the true source (m)")
ax.legend()
ax.grid(alpha=0.3, which="both")
fig.tight_layout()

# %%
# The search figure draws every robot's trajectory.
scenario, result = results[3]
draw_search_figure(result, scenario, make_truth(scenario, 0))
