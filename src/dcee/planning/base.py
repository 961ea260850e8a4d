"""Planner interface, the belief it sees, and the registry that names planners."""

from __future__ import annotations

import difflib
import inspect
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from dcee.errors import DceeInputError
from dcee.models.agent import GridAgent
from dcee.models.plume import IsotropicPlume
from dcee.models.sensor import Sensor

if TYPE_CHECKING:
    from dcee.models.site import SiteMap
    from dcee.planning.particle_terms import ParticleTerms


@dataclass(frozen=True)
class Belief:
    """A weighted particle approximation of p(Θ | Z_k), as planners see it (no copies made).

    theta: (N, 8) source terms; weights: (N,) normalised; sensor and plume: the models used to
    predict readings; cache: a :class:`~dcee.planning.particle_terms.ParticleTerms` kept by the
    caller across decisions (a :class:`~dcee.searcher.Searcher` keeps one), or None for a
    fresh one per decision.
    """

    theta: np.ndarray
    weights: np.ndarray
    sensor: Sensor
    plume: IsotropicPlume
    cache: ParticleTerms | None = field(default=None, compare=False, repr=False)
    site: SiteMap | None = field(default=None, compare=False, repr=False)
    """the site's obstacles and no-go zones (:class:`~dcee.models.site.SiteMap`): distance
    costs are travel distances around them; None: open terrain"""
    _variances: dict[int, float] = field(
        default_factory=dict, init=False, compare=False, repr=False
    )

    def __post_init__(self) -> None:
        # a wrong shape would otherwise be read as other columns and give silent nonsense
        if np.ndim(self.theta) != 2 or np.shape(self.theta)[1] != 8:
            raise DceeInputError("theta", f"must have shape (N, 8), got {np.shape(self.theta)}")
        if np.shape(self.weights) != (np.shape(self.theta)[0],):
            raise DceeInputError(
                "weights", f"must have shape ({len(self.theta)},), got {np.shape(self.weights)}"
            )

    @property
    def source(self) -> np.ndarray:
        """(N, 3) source locations."""
        return self.theta[:, :3]

    def source_mean(self) -> np.ndarray:
        return self.weights @ self.source

    def location_variance(self, dims: int = 3) -> float:
        """Σ of the posterior variances of the first ``dims`` source coordinates, m² (3: tr P of
        the location; 2: the horizontal part). Computed once per belief and ``dims`` (a tree
        search's cost asks for it at every expansion)."""
        if dims not in self._variances:
            loc = self.source[:, :dims]
            centred = loc - self.weights @ loc
            self._variances[dims] = float(self.weights @ np.einsum("ij,ij->i", centred, centred))
        return self._variances[dims]


@dataclass
class Decision:
    """A planner's choice among the admissible candidates.

    candidates: (M, 3) admissible next positions; costs: (M,) the planner's cost of each (lower is
    better); index: the chosen candidate; heading: its heading index in the agent's move set.
    """

    index: int
    candidates: np.ndarray
    costs: np.ndarray
    headings: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def position(self) -> np.ndarray:
        return self.candidates[self.index]

    @property
    def heading(self) -> int:
        return int(self.headings[self.index])


ENTRY_INSET = 1e-6
"""m: how far inside the search volume's face :func:`entry_point` puts its point (inside, not
on the face, whatever the rounding of a robot's position)."""


def entry_point(agent: GridAgent, position: np.ndarray) -> np.ndarray | None:
    """(3,) the point of the search volume nearest ``position`` (m), for a sensor outside the
    volume with no admissible move (a UAV taking off from a base beyond the area's edge, a
    robot's first pose a few metres outside it): the waypoint that brings it in. None when the
    position is inside the volume (no move there is another matter) or the nearest point is
    blocked by the site (the planners' moves never end in a blocked cell)."""
    p = np.asarray(position, dtype=np.float64)
    low, high = (np.asarray(c, dtype=np.float64) for c in (agent.volume.low, agent.volume.high))
    if bool(agent.volume.contains(p[None])[0]):
        return None
    inset = np.minimum(ENTRY_INSET, (high - low) / 2)
    entry = np.clip(p, low + inset, high - inset)
    site = getattr(agent, "site", None)
    if site is not None and bool(site.is_blocked(entry[None, :2])[0]):
        return None
    return entry


def entry_decision(agent: GridAgent, position: np.ndarray) -> Decision | None:
    """For a sensor outside the search volume, beyond one move of it: the :class:`Decision`
    to head for :func:`entry_point` first (its one candidate; heading −1, no move of the
    agent's set; ``info`` ``{"entry": True}``). None where :func:`entry_point` is."""
    entry = entry_point(agent, position)
    if entry is None:
        return None
    return Decision(0, entry[None, :], np.zeros(1), np.array([-1]), {"entry": True})


class Planner(ABC):
    """Chooses the next measurement position from the current belief.

    Subclasses implement :meth:`costs`; the choice is the admissible candidate of least cost
    (ties go to the lowest heading index, so decisions are deterministic).
    """

    name: ClassVar[str] = ""
    summary: ClassVar[str] = ""
    """One line for listings (``dcee strategies``)."""
    uses_hypotheses: ClassVar[bool] = False
    """True if the planner accepts ``n_hypotheses`` (hypothesised readings per candidate)."""
    follows_lookahead: ClassVar[bool] = False
    """True if the planner's ``horizon`` defaults to the scenario's look-ahead
    (``search.lookahead``, :attr:`dcee.scenarios.Scenario.lookahead`): ``dcee-cl``."""

    @abstractmethod
    def costs(
        self,
        belief: Belief,
        position: np.ndarray,
        candidates: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """(M,) cost of moving to each of the (M, 3) candidates, plus diagnostic info."""

    def decide(
        self,
        belief: Belief,
        position: np.ndarray,
        agent: GridAgent,
        rng: np.random.Generator,
    ) -> Decision:
        candidates, headings = agent.candidates(position)
        if len(candidates) == 0:
            entry = entry_decision(agent, position)
            if entry is None:
                raise DceeInputError("position", f"no admissible move from {position}")
            return entry
        costs, info = self.costs(belief, np.asarray(position, float), candidates, agent, rng)
        return Decision(int(np.argmin(costs)), candidates, costs, headings, info)

    def options(self) -> dict[str, Any]:
        """The planner's settings (saved with results)."""
        return {}


_REGISTRY: dict[str, type[Planner]] = {}
ENTRY_POINT_GROUP = "dcee.planners"
"""Entry-point group through which other packages add planners: an entry point ``NAME =
"package.module:PlannerClass"`` registers ``PlannerClass`` as ``NAME`` (loaded on first use of
the registry; a built-in name wins)."""
_entry_points_loaded = False


def register(name: str) -> Callable[[type[Planner]], type[Planner]]:
    """Class decorator: make a planner available as ``dcee.planners.get(name)``."""

    def wrap(cls: type[Planner]) -> type[Planner]:
        if name in _REGISTRY and _REGISTRY[name] is not cls:
            raise ValueError(f"planner name {name!r} already registered")
        cls.name = name
        _REGISTRY[name] = cls
        return cls

    return wrap


def unregister(name: str) -> None:
    """Remove a registered planner (for tests and notebooks that register their own)."""
    _REGISTRY.pop(name, None)


def _load_entry_points() -> None:
    """Register the planners other packages declare in :data:`ENTRY_POINT_GROUP` (once)."""
    global _entry_points_loaded
    if _entry_points_loaded:
        return
    _entry_points_loaded = True
    from importlib.metadata import entry_points

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in _REGISTRY:
            continue
        try:
            cls = ep.load()
        except Exception as exc:  # a broken plug-in must not break the built-in planners
            import warnings

            warnings.warn(f"planner entry point {ep.name!r} failed to load: {exc}", stacklevel=2)
            continue
        if isinstance(cls, type) and issubclass(cls, Planner):
            register(ep.name)(cls)


def check_count(field: str, value: object) -> int:
    """``value`` as an int >= 1, or :class:`DceeInputError` naming ``field`` (planner options
    arrive from specs and files as int, float or text)."""
    ok = (
        isinstance(value, int | float | np.integer | np.floating)
        and not isinstance(value, bool)
        and float(value).is_integer()
        and value >= 1
    )
    if not ok:
        raise DceeInputError(field, f"must be an integer >= 1, got {value!r}")
    return int(value)


OPTION_ALIASES = {"hypotheses": "n_hypotheses"}
"""Spec keys that name a constructor argument differently (as the scenario files do)."""


def parse_spec(spec: str) -> tuple[str, dict[str, Any]]:
    """Split a planner spec ``NAME[:KEY=VALUE]...`` into its registered name and options.

    ``"dcee-cl:reach=6:expectation=sampled"`` → ``("dcee-cl", {"reach": 6, "expectation":
    "sampled"})``. Values are read as int, float or true/false where they parse, else kept as
    text; the planner's constructor checks them. Malformed specs are user errors.
    """
    if not isinstance(spec, str) or not spec.strip():
        raise DceeInputError("strategy", f"must be a planner name, got {spec!r}")
    name, *parts = spec.strip().split(":")
    options: dict[str, Any] = {}
    for part in parts:
        key, sep, text = part.partition("=")
        key = key.strip()
        if not sep or not key or not text.strip():
            raise DceeInputError(
                "strategy", f"{spec!r}: options are KEY=VALUE after the name, got {part!r}"
            )
        options[OPTION_ALIASES.get(key, key)] = _option_value(text.strip())
    return name.strip(), options


def _option_value(text: str) -> Any:
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def planner_class(spec: str) -> type[Planner]:
    """The registered planner class of a name or spec; unknown names are a user error."""
    name = parse_spec(spec)[0]
    _load_entry_points()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise DceeInputError(
            "strategy", f"unknown planner {name!r}; choose one of {', '.join(names())}"
        ) from None


def get(spec: str, **defaults: Any) -> Planner:
    """A new planner from a registered name or spec ``NAME[:KEY=VALUE]...``; the spec's options
    override ``defaults``, and both go to the planner's constructor."""
    cls = planner_class(spec)
    options = {**defaults, **parse_spec(spec)[1]}
    try:
        return cls(**options)
    except TypeError as exc:
        allowed = constructor_options(cls)
        unknown = [k for k in options if k not in allowed]
        if not unknown:
            raise DceeInputError("planner_options", f"{spec}: {exc}") from None
        raise unknown_option(spec, unknown[0], allowed) from None


def unknown_option(spec: str, key: str, allowed: set[str]) -> DceeInputError:
    """The one-line error of a planner option that does not exist, with the closest match."""
    close = difflib.get_close_matches(key, sorted(allowed), n=1)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return DceeInputError(
        "strategy",
        f"{spec}: no option {key!r}{hint} (options: {', '.join(sorted(allowed))})",
    )


def constructor_options(cls: type[Planner]) -> set[str]:
    """The keyword options a planner class accepts: its constructor's named parameters and,
    where it forwards ``**kwargs`` to a base class, the base's."""
    out: set[str] = set()
    for klass in cls.__mro__:
        init = klass.__dict__.get("__init__")
        if init is None:
            continue
        params = inspect.signature(init).parameters.values()
        out |= {p.name for p in params if p.name != "self" and p.kind is not p.VAR_KEYWORD}
        if not any(p.kind is p.VAR_KEYWORD for p in params):
            break
    return out


def names() -> list[str]:
    """Registered planner names (built-in and from the ``dcee.planners`` entry points)."""
    _load_entry_points()
    return sorted(_REGISTRY)
