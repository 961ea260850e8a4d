"""
# A robot's ask/tell loop

A robot drives `dcee.Searcher` directly: after every sample it *tells* the searcher where it was
and what the sensor read, then *asks* where to sample next. Here a simulated sensor stands in
for the robot's (`sensor.simulate_from` on the true concentration); on a robot the reading
comes from the instrument and the position from localisation. Everything random comes from
explicit seeded generators, so the run is reproducible. Half-way, the robot "restarts": it
checkpoints the searcher and carries on with the restored one, which decides exactly as the
uninterrupted one would have. The loop ends when the searcher says the source is localised
(`searcher.localised`: the posterior spread has stayed below the stop rule's threshold for its
hold, here the scenario's default, 0.15 × its 0.5 m "acquired" bar for 60 s) or the budget is
spent.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import dcee
from dcee.scenarios import load_scenario
from dcee.simulation import IsotropicTruth

scenario = load_scenario("lab:downwind")  # the paper's 4.5 m × 3.5 m room, 7 unknowns
pf = dcee.ParticleFilter(
    scenario.make_prior(),
    scenario.make_estimator_sensor(),  # the reading model the filter assumes
    scenario.make_plume(),
    n_particles=3000,
    seed=np.random.default_rng(1),
)
searcher = dcee.Searcher(
    pf,
    dcee.planners.get("dcee-cl", n_hypotheses=20),
    scenario.make_agent(),
    np.random.default_rng(2),
    stop_rule=scenario.stop_rule(on_robot=True),  # the lab's scale; None: never stop early
)

truth = IsotropicTruth(scenario.truth_theta())  # what the robot's sensor really sees
sensor = scenario.make_sensor()
noise_rng = np.random.default_rng(3)
position = np.array(scenario.agent.start, dtype=float)
t, step_time = 0.0, scenario.make_agent().step_time
path, spreads = [position.copy()], []
checkpoint = Path(tempfile.mkdtemp()) / "search.ckpt"
k = 0
while not searcher.localised and t + step_time <= scenario.search.budget:
    if k == 40:  # a restart mid-search: save, then carry on with the restored searcher
        searcher.save(checkpoint)
        searcher = dcee.Searcher.load(checkpoint)
        pf = searcher.filter
    reading = float(
        sensor.simulate_from(truth.concentration(position, t), sensor.draw_noise(noise_rng, ()))
    )
    searcher.tell(position, reading, t)  # what the robot measured, where and when
    spreads.append(searcher.estimate().spread)
    position = searcher.ask()  # the next waypoint (m); a robot would drive there
    path.append(position.copy())
    t += step_time
    k += 1

est = searcher.estimate()
source = scenario.truth_theta()[:3]
print(f"estimate {np.round(est.mean, 2)} m, truth {source}, spread {est.spread:.2f} m")
print(f"error of the mean: {np.linalg.norm(est.mean - source):.2f} m after {len(spreads)} readings")
print("stopped:", "source localised" if searcher.localised else "budget spent", f"at {t:.0f} s")

# %%
# The particles' source locations (weighted sample), the path and the true source; right, the
# posterior spread over the readings.

fig, (ax, ax2) = plt.subplots(1, 2, figsize=(10, 4), layout="constrained")
sample = pf.source_locations[np.random.default_rng(4).choice(pf.n, 1000, p=pf.weights)]
ax.scatter(sample[:, 0], sample[:, 1], s=2, alpha=0.4, label="particles")
p = np.array(path)
ax.plot(p[:, 0], p[:, 1], "r.-", lw=1, label="path")
ax.plot(*source[:2], "*", color="gold", mec="k", ms=14, label="source")
lo, hi = scenario.volume.low, scenario.volume.high
ax.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), aspect="equal", xlabel="x (m)", ylabel="y (m)")
ax.legend(loc="upper right", fontsize=8)
ax2.semilogy(np.arange(len(spreads)) * step_time, spreads)
ax2.set(xlabel="time (s)", ylabel="posterior spread (m)")
plt.show()
