"""Plan a chain of five through the `window` scenario, check the plan exactly, fly it,
and draw the plan and the flight from above and from the side (matplotlib, PNG).

    python python/examples/plan_window.py [window.png]
"""

import sys

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import aerial_chain as ac


def main(out="window.png"):
    world = ac.Map.scenario("window")
    plan = ac.plan(world, units=5)
    report = ac.verify(world, plan)  # raises VerifyError if INVALID
    flight = ac.simulate(world, plan)
    print(f"{plan}: VALID, minimum clearance {report.min_clearance:.3f} m; {flight}")

    units = plan.unit_positions()  # (waypoints, N, 3)
    heads = plan.heads
    flown = flight.unit_positions[:, 0, :]  # the head's flown track
    changes = [i + 1 for i, e in enumerate(report.edges) if e == "shape_change"]
    colours = plt.cm.viridis(np.linspace(0, 1, len(plan)))
    # From above: the voxels in the chain's height band. From the side: a cut through
    # the window (one voxel either side of the goal's y), so the opening shows.
    z_lo, z_hi = units[..., 2].min() - 0.2, units[..., 2].max() + 0.2
    y_cut = world.goal[1]
    voxels = world.occupied_voxels()
    cut = voxels[np.abs(voxels[:, 1] - y_cut) <= world.resolution]
    views = [
        ("from above", 0, 1, "y (m)", world.occupied_voxels(z_range=(z_lo, z_hi))),
        (f"from the side, cut at y = {y_cut:.1f} m", 0, 2, "z (m)", cut),
    ]

    fig, axes = plt.subplots(
        1, 2, figsize=(14, 5.6), constrained_layout=True
    )
    for ax, (title, a, b, label, obstacles) in zip(axes, views):
        ax.scatter(obstacles[:, a], obstacles[:, b], s=5, c="0.7", marker="s",
                   linewidths=0, label="obstacles")
        for i, chain in enumerate(units):
            ax.plot(chain[:, a], chain[:, b], "-o", color=colours[i], ms=3.5, lw=1.5)
        ax.plot(flown[:, a], flown[:, b], color="tab:orange", lw=3, alpha=0.6,
                label="flown head (simulation)")
        ax.plot(heads[:, a], heads[:, b], "--", color="k", lw=1, label="planned head route")
        ax.plot(heads[changes, a], heads[changes, b], "D", color="tab:red", ms=6,
                ls="none", label="shape change ends")
        ax.plot(*world.start[[a, b]], "^", color="tab:blue", ms=9, ls="none", label="start")
        ax.plot(*world.goal[[a, b]], "*", color="tab:green", ms=14, ls="none", label="goal")
        lo, hi = world.bounds
        ax.set(xlim=(lo[a], hi[a]), ylim=(lo[b], hi[b]), xlabel="x (m)", ylabel=label)
        ax.set_aspect("equal")
        ax.set_title(f"window, N = {plan.units}, {title}")
    axes[0].legend(loc="lower left", fontsize=8, framealpha=0.95)
    ramp = plt.cm.ScalarMappable(cmap="viridis", norm=plt.Normalize(0, len(plan) - 1))
    bar = fig.colorbar(ramp, ax=axes, label="waypoint (the chain at each)", shrink=0.7,
                       ticks=range(len(plan)))
    bar.ax.tick_params(labelsize=8)
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
