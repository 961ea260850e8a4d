"""Scenario configuration: TOML validated on load into immutable objects.

The package in three parts: the schema (:mod:`dcee.scenarios.schema`, pydantic models), the
builders that turn a scenario into model objects (:mod:`dcee.scenarios.builders`), and the files
(:mod:`dcee.scenarios.files`: load, write TOML, read ``--set``); the built-in scenarios are
:mod:`dcee.scenarios.builtin`.

A scenario is a TOML file (or a built-in, see :mod:`dcee.scenarios.builtin`)::

    name = "my-site"
    dimensions = 3                 # 3: source z unknown in "source"; 2: z known, planar search
    unknown = "source"             # "source": x, y, (z), q unknown; "full": all parameters unknown

    [volume]                       # search volume in m; the location prior is uniform over it
    low = [0.0, 0.0, 0.0]
    high = [50.0, 50.0, 5.0]

    [truth]                        # ground-truth source term (angles in degrees)
    x = 37.5
    y = 12.5
    z = 1.0
    q = 5.0                        # g/s
    u = 4.0                        # m/s
    phi = 0.0                      # deg; wind comes FROM this direction
    zeta1 = 1.0
    zeta2 = 8.0
    model = "isotropic"            # or "filament", or { file = "plume.h5" } (recorded plume)

    [prior]                        # used for unknown parameters; degrees for phi
    q = { kind = "gamma", shape = 2.0, scale = 5.0 }
    u = { kind = "normal", mean = 4.0, sd = 1.414 }
    phi = { kind = "normal", mean = 0.0, sd = 3.162 }
    zeta1 = { kind = "normal", mean = 1.0, sd = 1.414 }
    zeta2 = { kind = "normal", mean = 8.0, sd = 1.414 }

    [sensor]                       # g/m³
    threshold = 5e-4
    pd = 0.7
    sigma_min = 1e-4
    sigma_frac = 0.5
    false_alarm = 0.0
    max_reading = 1e4              # physical maximum; larger readings are refused
    dropout = 0.0                  # simulated misses [default: 1 - pd isotropic, 0 turbulent]
    average = 5.0                  # s averaged at the end of each hold [default: see SensorSpec]

    [estimator]                    # the reading model of the filter and the planners
    likelihood = "paper"           # or "fluctuation" (intermittent log-normal, for real plumes)
    intermittency = 0.93           # fluctuation only
    log_sd = 1.3                   # fluctuation only
    near_source_length = 0.5       # fluctuation only, m
    calm_prior = 0.1               # fluctuation only: prior probability of a calm plume (0: off)
    meander = 0.15                 # plume broadening [default: 0 paper, 0.15 fluctuation]
    outlier = 0.01                 # outlier weight [default: 0.01 for every likelihood]
    magnitude = true               # fluctuation only; false: detection-only readings
    conserve_mean = true           # fluctuation only: a detection's mean is C / Pd(r)
    repeat_radius = 2.0            # m, a run at one spot discounted [default: 0 paper, 2 fluct.]
    repeat_power = 0.5             # its discount 1 / (1 + m)^p [default: 1 paper, 0.5 fluct.]

    [agent]
    start = [2.0, 2.0, 4.0]        # m; the agent flies at the start altitude
    step = 2.0                     # m
    climb = 0.0                    # m per climb or descent move; 0: fixed altitude (the paper)
                                   #  [default: 1 with the fluctuation likelihood, else 0]
    speed = 2.0                    # m/s
    dwell = 1.0                    # s held at each waypoint [default: 1, 5 if time-varying]

    [search]
    particles = 20000
    hypotheses = 40                # hypothesised readings per candidate move
    budget = 900.0                 # s of flight
    acquired_rmse = 3.0            # m; "source acquired" when the final RMSE is below this
    # stop_spread = 0.45           # m; end once the posterior spread stays below it for
    # stop_hold = 60.0             # s [default: a robot stops at 0.15 x acquired_rmse, a
                                   #  simulated study flies the whole budget; 0: never stop]
    stall_guard = 30.0             # s within one step of one spot before a move must leave it
    guard_share = 0.15             # ... while the spread exceeds this share of acquired_rmse

Normal priors are truncated to physical values (u ≥ 0, ζ1 > 0, ζ2 > 0) automatically.
"""

from dcee.scenarios.builtin import builtin_scenarios
from dcee.scenarios.files import (
    expand_names,
    load_scenario,
    parse_setting,
    to_toml,
    truth_choice,
)
from dcee.scenarios.schema import *  # noqa: F403  (the schema's public names)
from dcee.scenarios.schema import __all__ as _schema_names

__all__ = [
    *_schema_names,
    "builtin_scenarios",
    "expand_names",
    "load_scenario",
    "parse_setting",
    "to_toml",
    "truth_choice",
]
