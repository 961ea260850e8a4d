"""
# A campaign in pandas

`dcee bench` runs many searches and saves each one; `dcee.analysis.results` loads them all in
one call, as a table of summaries or of every reading. Here a tiny campaign (2 configurations ×
2 repeats × 2 strategies, 500 particles) runs in this process; a real study is
`dcee bench --suite paper --repeats 10 --out results/study`, read the same way.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from dcee.analysis.results import load_steps, load_summaries
from dcee.campaign import Campaign
from dcee.campaign.runner import run_search

folder = Path(tempfile.mkdtemp()) / "study"
campaign = Campaign(folder, "smoke", ("mpc", "infotaxis"), repeats=2, particles=500)
campaign.prepare()  # writes campaign.json (settings and code version)
for task in campaign.tasks():  # `dcee bench` runs these on worker processes
    run_search(task)

runs = load_summaries(folder)
print(runs.groupby("strategy")[["final_rmse", "detections"]].median())

# %%
# Every reading of every search, with the search's scenario, strategy and seed as columns.

steps = load_steps(folder, ["time", "rmse"])
print(steps.head())
median = steps.groupby(["strategy", "time"])["rmse"].median().unstack("strategy")
ax = median.plot(logy=True, figsize=(7, 4), xlabel="time (s)", ylabel="median RMSE (m)")
plt.show()
