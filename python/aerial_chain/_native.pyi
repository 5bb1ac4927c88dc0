"""Type stubs of the extension module ``aerial_chain._native`` (PyO3), which the package
``aerial_chain`` re-exports. Checked against the built module by
``python/tests/test_stubs.py``: every name here exists there and the other way round,
with the same parameters."""

from os import PathLike
from typing import Any, Final, Optional, Sequence, Tuple, Union, final

import numpy as np
from numpy.typing import NDArray

_Path = Union[str, PathLike[str]]
_Point = Union[Sequence[float], NDArray[np.float64]]

__all__ = [
    "ArcError",
    "DEFAULT_CLEARANCE",
    "Exploration",
    "ExploreError",
    "ExportError",
    "Flight",
    "Map",
    "MapError",
    "OnlinePlanner",
    "Plan",
    "PlanError",
    "SCENARIOS",
    "SimError",
    "VerifyError",
    "VerifyReport",
    "explore",
    "export",
    "plan",
    "simulate",
    "verify",
]

DEFAULT_CLEARANCE: Final[float]
"""The clearance margin (m) every plan keeps from the map by default."""

SCENARIOS: Final[list[str]]
"""Names of the built-in scenarios."""

class ArcError(ValueError):
    """Base of the errors of aerial_chain: bad input, or an answer that is no."""

class MapError(ArcError):
    """A map that cannot be loaded: a missing or malformed .bt file, an unknown scenario."""

class PlanError(ArcError):
    """Planning refused or failed: bad chain or query, no plan found; or a bad plan file."""

class VerifyError(ArcError):
    """The exact verifier found the plan INVALID on the map (the message says where)."""

class SimError(ArcError):
    """The simulation cannot fly the plan: settings outside their limits, a plan it cannot time."""

class ExportError(ArcError):
    """An export that cannot be made: an output name that is no .mcap or .tlog, options outside their limits."""

class ExploreError(ArcError):
    """An exploration that cannot run: sensor or planner settings outside their limits, a start whose hull is not free."""

@final
class Map:
    """A map to plan, verify and fly on: an occupancy grid (OctoMap ``.bt`` file or
    built-in scenario) and whether unknown space counts as occupied."""

    @staticmethod
    def from_file(path: _Path, unknown_free: bool = False) -> Map:
        """Reads an OctoMap binary tree (``.bt``); raises ``MapError`` naming the file."""
    @staticmethod
    def scenario(name: str, unknown_free: bool = False) -> Map:
        """A built-in scenario (``SCENARIOS``, ``corridor:LENGTH``, ``passage:...``,
        ``forest:...``, ``slot:...``, ``pipe:...``, ``shaft:...``, ``campus``, ``hall``)."""
    @property
    def name(self) -> str:
        """The map's name: the file or ``scenario NAME``."""
    @property
    def resolution(self) -> float:
        """Voxel edge (m)."""
    @property
    def unknown_is_occupied(self) -> bool:
        """Whether unknown space counts as occupied."""
    @property
    def bounds(self) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The grid's metric bounds ``(lo, hi)``, two arrays of 3 (m)."""
    @property
    def start(self) -> Optional[NDArray[np.float64]]:
        """The scenario's head start (array of 3, m); ``None`` for a map file."""
    @property
    def goal(self) -> Optional[NDArray[np.float64]]:
        """The scenario's head goal (array of 3, m); ``None`` for a map file."""
    def scan(
        self,
        position: _Point,
        yaw: float = 0.0,
        attitude: Optional[Sequence[float]] = None,
        sensor: Optional[dict[str, Any]] = None,
        unit: int = 0,
    ) -> Tuple[NDArray[np.float64], NDArray[np.float64], float]:
        """What one unit's depth sensor measures in this map, as ``arc explore``'s
        simulated sensors cast it: ``(origin, points, max_range)``, the arguments of
        ``OnlinePlanner.observe``."""
    @property
    def start_yaw(self) -> Optional[float]:
        """The scenario's start yaw (rad); ``None`` for a map file."""
    @property
    def default_units(self) -> Optional[int]:
        """The number of units the scenario is made for; ``None`` for a map file."""
    def occupied_voxels(
        self, z_range: Optional[Tuple[float, float]] = None
    ) -> NDArray[np.float64]:
        """Centres of the occupied voxels, ``(K, 3)`` (m), optionally in a height band."""

@final
class Plan:
    """A plan (``arc-plan/1``): waypoints of the chain, the start first."""

    @staticmethod
    def read(path: _Path) -> Plan:
        """Reads and checks a plan file; raises ``PlanError`` naming the file and field."""
    @staticmethod
    def from_json(text: str, name: str = "<plan>") -> Plan:
        """Parses and checks a plan's JSON text."""
    def write(self, path: _Path) -> None:
        """Writes the plan file (pretty JSON, atomically)."""
    def to_json(self) -> str:
        """The plan as JSON text."""
    @property
    def units(self) -> int:
        """Number of units N."""
    @property
    def chain(self) -> dict[str, Any]:
        """The chain section (units, link_length, unit_radius, ...)."""
    @property
    def map(self) -> dict[str, Any]:
        """The map section: resolution, unknown_is_occupied, the map's source."""
    @property
    def stats(self) -> dict[str, Any]:
        """The planner's statistics (counts, timings in seconds, quality)."""
    @property
    def waypoints(self) -> NDArray[np.float64]:
        """Every waypoint's configuration zeta, ``(W, 2N + 2)`` (m, rad)."""
    @property
    def heads(self) -> NDArray[np.float64]:
        """The head position of every waypoint, ``(W, 3)`` (m)."""
    def unit_positions(self) -> NDArray[np.float64]:
        """Every unit's centre at every waypoint, ``(W, N, 3)`` (m, head first)."""
    def __len__(self) -> int: ...

@final
class VerifyReport:
    """What the exact verifier found (``arc verify``)."""

    @property
    def ok(self) -> bool:
        """True when the plan is VALID and starts and ends where asked."""
    @property
    def violation(self) -> Optional[str]:
        """Why the plan is INVALID (``None`` when valid)."""
    @property
    def samples(self) -> int:
        """Configurations tested."""
    @property
    def min_clearance(self) -> float:
        """Smallest clearance of any body to the map over the valid samples (m)."""
    @property
    def min_clearance_at(self) -> Optional[str]:
        """Where that clearance was found."""
    @property
    def edges(self) -> list[str]:
        """The kind of every edge: ``translation``, ``shape_change``, ``stay`` or ``both``."""
    @property
    def notes(self) -> list[str]:
        """Remarks: another map than the plan's, a different unknown-space assumption."""

@final
class Flight:
    """A flight: the chain's recorded states and its report; arrays are ``(T, ...)``."""

    @property
    def t(self) -> NDArray[np.float64]:
        """Time of every sample, ``(T,)`` (s)."""
    @property
    def unit_positions(self) -> NDArray[np.float64]:
        """Every unit's centre, ``(T, N, 3)`` (m, head first)."""
    @property
    def unit_states(self) -> NDArray[np.float64]:
        """Every unit's rigid-body state, ``(T, N, 13)``: position, quaternion
        ``[w, x, y, z]``, velocity, angular velocity (world frame)."""
    @property
    def head_reference(self) -> NDArray[np.float64]:
        """The reference head position the controller tracked, ``(T, 3)`` (m)."""
    @property
    def report(self) -> dict[str, Any]:
        """The summary (``arc sim --out``'s ``report``)."""
    @property
    def success(self) -> bool:
        """True when the chain reached the plan's goal without touching anything."""
    def __len__(self) -> int: ...

@final
class Exploration:
    """What ``explore`` returns: how the run ended, the flight, the committed pieces as
    one plan, the record of every replan and the map the sensors drew."""

    @property
    def reached(self) -> bool:
        """True when the chain reached the goal and settled there."""
    @property
    def end(self) -> dict[str, Any]:
        """How the run ended: ``kind`` (``reached``, ``sealed``, ``stuck``,
        ``time_limit``, ``flight_failed``), the simulated time ``t`` and, but for
        ``reached``, why."""
    @property
    def flight(self) -> Flight:
        """The flight: the chain's states and its report against the true map."""
    @property
    def plan(self) -> Plan:
        """The committed pieces joined into one plan (``arc explore --plan-out``)."""
    @property
    def replans(self) -> list[dict[str, Any]]:
        """Every replan, in order (docs/model.md, "Explorations")."""
    @property
    def summary(self) -> dict[str, Any]:
        """Replans, pieces, replan latency, field updates, voxels seen."""
    @property
    def seen_growth(self) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The map as it grew: the centres (K, 3) of the seen map's occupied voxels in
        the order they were seen, and when each was first seen occupied (K,)."""
    @property
    def voxels_seen(self) -> int:
        """Voxels of the seen map known (free or occupied) at the end."""
    def write_seen(self, path: _Path) -> None:
        """Writes the map the sensors drew (``.bt``, as ``arc explore --map-out``)."""
    def write(self, path: _Path) -> None:
        """Writes the flight with the record of every replan (``arc-sim/1``, as ``arc
        explore --out``)."""

@final
class OnlinePlanner:
    """The online planner one replan at a time, for a robot's own loop (docs/online.md):
    feed it clouds and flown unit centres, ask which replan is ``due``, ``replan``, and
    fly ``committed``. Times are the caller's clock (s); points are in the map's frame."""

    def __new__(
        cls,
        map: Map,
        units: Optional[int] = None,
        start: Optional[_Point] = None,
        goal: Optional[_Point] = None,
        start_yaw: Optional[float] = None,
        start_shape: Optional[Sequence[float]] = None,
        goal_tol: float = 0.3,
        deadline: float = ...,
        clearance: float = ...,
        start_free: str = "hull",
        sensor: Optional[dict[str, Any]] = None,
        known: Optional[Map] = None,
    ) -> OnlinePlanner:
        """A planner in the box of ``map`` (its contents are not read): nothing is known
        but ``known`` and the start's own space. Raises ``PlanError`` for a bad chain
        or query, ``ExploreError`` for bad settings."""
    def observe(
        self, origin: _Point, points: Union[Sequence[_Point], NDArray[np.float64]], max_range: float
    ) -> int:
        """Fuses one sensor's cloud (an (M, 3) array of returns, a miss as a point
        beyond ``max_range``) as OctoMap's ``insertPointCloud``; the voxels changed."""
    def observe_flown(self, centres: Union[Sequence[_Point], NDArray[np.float64]]) -> int:
        """Marks the balls of ``r_u`` plus the clearance about the unit centres seen
        free; the voxels changed."""
    def due(self, now: float, period: float = ...) -> Optional[str]:
        """The replan due at ``now`` (``commit_short``, ``route_cut``, ``period``) for a
        caller observing every ``period`` s, or ``None``."""
    def replan(self, now: float, trigger: str) -> dict[str, Any]:
        """Replans for ``trigger`` (``start``, ``route_cut``, ``period``,
        ``commit_short``) and returns its record (docs/model.md, "Explorations")."""
    def committed(
        self, dt: float = 0.02
    ) -> Tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The committed motion sampled every ``dt`` s: times (K,) and configurations
        (K, 2N + 2)."""
    def at(self, t: float) -> NDArray[np.float64]:
        """The committed configuration zeta at time ``t`` (the end after it ends)."""
    def follow_at_ticks(self, period: float) -> None:
        """Makes a changed committed motion take effect on the follower's ticks of
        ``period`` s (0: at once)."""
    @property
    def effective_from(self) -> float:
        """When the committed motion as it is now may be flown (s)."""
    @property
    def committed_until(self) -> float:
        """When the committed motion ends, at rest (s)."""
    @property
    def reached(self) -> bool:
        """True once the committed motion ends at the goal."""
    def stuck(self, now: float) -> Optional[str]:
        """Why the chain can get no further at ``now``, or ``None``."""
    @property
    def route(self) -> Optional[NDArray[np.float64]]:
        """The route to the goal as last searched (unknown space free), (P, 3)."""
    @property
    def pieces(self) -> int:
        """Pieces committed so far (turns to look included)."""
    @property
    def replans(self) -> list[dict[str, Any]]:
        """Every replan so far, as ``replan`` returned them."""
    @property
    def voxels_seen(self) -> int:
        """Voxels of the seen map known (free or occupied)."""
    def plan(self) -> Plan:
        """The committed pieces joined into one plan (``arc explore --plan-out``)."""
    def write_seen(self, path: _Path) -> None:
        """Writes the seen map (``.bt``)."""

def explore(
    map: Map,
    units: Optional[int] = None,
    start: Optional[_Point] = None,
    goal: Optional[_Point] = None,
    start_yaw: Optional[float] = None,
    start_shape: Optional[Sequence[float]] = None,
    goal_tol: float = 0.3,
    time_limit: float = 600.0,
    deadline: float = ...,
    clearance: float = ...,
    start_free: str = "hull",
    sensor: Optional[dict[str, Any]] = None,
    sensor_rate: float = ...,
    known: Optional[Map] = None,
    record_every: int = 10,
) -> Exploration:
    """Flies the chain into the unknown on ``map`` as ``arc explore`` does: only the
    units' simulated sensors (``sensor``: docs/maps.md "Sensing" fields) read ``map``;
    the online planner replans from what they saw. Raises ``PlanError`` for a bad chain
    or query, ``ExploreError`` for bad settings or a start that is not free,
    ``SimError`` when the simulation cannot run."""

def plan(
    map: Map,
    units: Optional[int] = None,
    start: Optional[_Point] = None,
    goal: Optional[_Point] = None,
    start_yaw: Optional[float] = None,
    start_shape: Optional[Sequence[float]] = None,
    goal_tol: float = 0.3,
    seed: int = 1,
    srs: int = 500,
    srs_seed: int = 1,
    clearance: float = ...,
    time_limit: Optional[float] = ...,
    smooth: bool = True,
    goal_yaw: Optional[float] = None,
    goal_shape: Optional[Union[str, Sequence[float]]] = None,
    mission: Optional[_Path] = None,
) -> Plan:
    """Plans on ``map`` with the ARCplanner and the defaults of ``arc plan`` (a time
    limit of 60 s; ``None``: none); ``goal_yaw`` (rad) and ``goal_shape`` end the plan
    in that configuration, ``mission`` (an ``arc-mission/1`` file) plans through its
    goals; raises ``PlanError`` for bad input and when no plan is found."""

def verify(
    map: Map,
    plan: Plan,
    start: Optional[_Point] = None,
    goal: Optional[_Point] = None,
    goal_tol: float = 0.3,
    strict: bool = True,
) -> VerifyReport:
    """Checks ``plan`` on ``map`` with the exact verifier; raises ``VerifyError`` when
    INVALID unless ``strict=False``."""

def simulate(
    map: Map,
    plan: Plan,
    rate: float = 500.0,
    speed: float = 0.5,
    accel: float = 0.5,
    angular_rate: float = 0.4,
    yaw_rate: Optional[float] = None,
    goal_tol: float = 0.1,
    settle_time: float = 10.0,
    record_every: int = 10,
    blend: bool = True,
) -> Flight:
    """Flies ``plan`` on ``map`` with the chain's dynamics and control stack as ``arc
    sim`` does (along the plan's blended trajectory; ``blend=False``: stopping at every
    waypoint); ``angular_rate`` limits the link angles, ``yaw_rate`` the head yaw
    (``None``: ``arc sim``'s 45 deg/s); raises ``SimError`` for settings outside their limits."""

def export(
    map: Map,
    source: Union[Plan, Flight],
    path: _Path,
    rate: float = 50.0,
    sysid_base: int = 1,
    hold_s: float = 1.0,
    arm: bool = False,
    autopilot: str = "px4",
) -> int:
    """Writes a plan (timed as ``arc trajectory`` times it) or a flight as ``arc export``
    does: a ROS 2 bag when ``path`` ends in ``.mcap``, MAVLink 2 setpoints when it ends
    in ``.tlog``; returns the bytes written; raises ``ExportError``."""
