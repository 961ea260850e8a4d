"""
# Policies in the Gymnasium environment

`import dcee.gym` registers `dcee/SourceSearch-v0`, a Gymnasium environment around one
simulated search. A learned policy acts on the observation (a belief summary); the planners act
through `PlannerPolicy`, which reads the belief itself, and make exactly the decisions
`dcee run` makes for the same seed. `evaluate` scores any of them on the same seeds (the same
truth and sensor noise) with the summary `dcee run` writes.

Here a random policy (the floor any learned policy must beat), infotaxis and closed-loop DCEE
on three seeds of paper:1, with 2,000 particles and a 300 s budget (kept small so that the
documentation builds quickly).
"""

import gymnasium
import matplotlib.pyplot as plt

import dcee.gym

env = gymnasium.make(dcee.gym.ENV_ID, scenario="paper:1", particles=2000, budget=300.0)
obs, info = env.reset(seed=0)
print({k: round(float(v), 3) for k, v in zip(dcee.gym.OBSERVATION_FIELDS, obs, strict=True)})
print("admissible headings:", info["action_mask"])

policies = [
    dcee.gym.RandomPolicy(),
    dcee.gym.PlannerPolicy("infotaxis"),
    dcee.gym.PlannerPolicy("dcee-cl"),
]
table = dcee.gym.evaluate(policies, seeds=[0, 1, 2], make_env=lambda: env)
print(
    table.groupby("strategy")[["final_rmse", "source_acquired", "time_to_rmse_1m", "return"]]
    .agg(["median"])
    .round(2)
)

# %%
# The same comparison as RMSE over time, seed 0 (the environment keeps every record).
fig, ax = plt.subplots(figsize=(7, 3.6))
for policy in policies:
    obs, info = env.reset(seed=0)
    policy.reset(env, 0)
    done = False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy.act(env, obs, info))
        done = terminated or truncated
    records = env.unwrapped.simulation.records
    ax.semilogy([r["time"] for r in records], [r["rmse"] for r in records], label=policy.name)
ax.set_xlabel("time (s)")
ax.set_ylabel("RMSE about the true source (m)")
ax.legend()
ax.grid(alpha=0.3, which="both")
fig.tight_layout()
