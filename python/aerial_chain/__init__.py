"""The Aerial Robotic Chain from Python.

N quadrotors joined by rigid links, planned through OctoMap maps by the ARCplanner,
checked by the exact verifier and flown by the chain's simulation. A thin layer over
the Rust library ``aerial_chain`` (the ``arc`` command line uses the same code)::

    import aerial_chain as ac

    world = ac.Map.scenario("window")              # or ac.Map.from_file("map.bt")
    plan = ac.plan(world, units=5)                   # the defaults of `arc plan`
    ac.verify(world, plan)                           # raises VerifyError if INVALID
    plan.unit_positions()                            # (waypoints, N, 3) numpy array
    flight = ac.simulate(world, plan)                # flight.unit_positions: (T, N, 3)
    run = ac.explore(world, units=4)                 # into the unknown, as `arc explore`
    planner = ac.OnlinePlanner(world, units=4)       # the same, one replan at a time
    ac.export(world, plan, "window.mcap")            # a ROS 2 bag; .tlog: MAVLink

Bad input raises ``MapError``, ``PlanError``, ``VerifyError``, ``SimError``,
``ExploreError`` or ``ExportError``, all subclasses of ``ArcError`` (a
``ValueError``), with a message naming the file, field or argument and the value.
"""

from . import _native
from ._native import (
    DEFAULT_CLEARANCE,
    SCENARIOS,
    ArcError,
    Exploration,
    ExploreError,
    ExportError,
    Flight,
    Map,
    MapError,
    OnlinePlanner,
    Plan,
    PlanError,
    SimError,
    VerifyError,
    VerifyReport,
    explore,
    export,
    plan,
    simulate,
    verify,
)

# The compiled module lists its names; the stub (_native.pyi) lists the same ones, and
# type checkers follow this form of re-export.
__all__: list = []
__all__ += _native.__all__
