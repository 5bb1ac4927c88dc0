"""Flying into the unknown with a loop of your own: the online planner one replan at a
time (``aerial_chain.OnlinePlanner``), as a robot's software would drive it.

    python python/examples/explore_loop.py [SCENARIO] [UNITS]

Every sensor period the loop moves the chain to where the committed motion has it (a
perfect follower: a robot's controller would fly it), tells the planner the space the
bodies fill, scans the truth from every unit (``Map.scan``, which a real robot's depth
cameras replace) and fuses the clouds, then replans when one is due. The planner never
reads the world map: it plans from the clouds alone.
"""

import sys

import numpy as np

import aerial_chain as ac

# The sensors' rate (Hz), as `arc explore`'s default.
RATE_HZ = 10.0


def unit_centres(zeta, units, link_length=0.5):
    """The unit centres of configuration ``zeta`` (docs/model.md, "The chain"): each
    unit one link length behind the one before, along the link's absolute pitch and
    yaw."""
    p = [np.asarray(zeta[:3], dtype=float)]
    for i in range(units - 1):
        theta, psi = zeta[4 + 2 * i], zeta[5 + 2 * i]
        step = [np.cos(psi) * np.cos(theta), np.sin(psi) * np.cos(theta), -np.sin(theta)]
        p.append(p[-1] - link_length * np.asarray(step))
    return np.array(p)


def sense(world, planner, zeta, units):
    """Tells ``planner`` what the chain at ``zeta`` fills and what its units' sensors
    see of ``world`` (every unit holds the head's yaw ``zeta[3]``)."""
    centres = unit_centres(zeta, units)
    planner.observe_flown(centres)
    for i, c in enumerate(centres):
        planner.observe(*world.scan(c, yaw=zeta[3], unit=i))


def fly(world, units, time_limit=300.0):
    """Flies ``units`` units into ``world`` from its scenario's start to its goal;
    returns the planner and the time (s) the chain came to rest at the goal, or
    ``None`` when it did not. Raises ``RuntimeError`` when the chain is stuck."""
    period = 1.0 / RATE_HZ
    planner = ac.OnlinePlanner(world, units=units)
    planner.follow_at_ticks(period)
    now = 0.0
    sense(world, planner, planner.at(now), units)
    planner.replan(now, "start")
    while now < time_limit:
        now = round(now + period, 9)
        sense(world, planner, planner.at(now), units)
        if planner.reached and now >= planner.committed_until:
            return planner, planner.committed_until
        trigger = planner.due(now, period)
        if trigger:
            planner.replan(now, trigger)
        why = planner.stuck(now)
        if why:
            raise RuntimeError(f"stuck at {now:.1f} s: {why}")
    return planner, None


def main():
    name = sys.argv[1] if len(sys.argv) > 1 else "window"
    world = ac.Map.scenario(name)
    units = int(sys.argv[2]) if len(sys.argv) > 2 else world.default_units
    planner, at = fly(world, units)
    if at is None:
        sys.exit(f"{name}: the goal was not reached in time ({planner})")
    report = ac.verify(world, planner.plan())
    print(
        f"{name}, N = {units}: at the goal at {at:.1f} s, {planner.pieces} pieces, "
        f"{len(planner.replans)} replans, {planner.voxels_seen} voxels seen; the flown "
        f"plan is valid on the world (clearance {report.min_clearance:.3f} m)"
    )


if __name__ == "__main__":
    main()
