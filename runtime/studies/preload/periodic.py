"""Re-simulating a preload design from the scene's initial state until its revolution is periodic (the
machine's steady state), for one design or several at once."""

from __future__ import annotations

from .schedule import simulate_schedules

#: the re-simulation continues, 2 revolutions at a time (up to 12 in all), until the state at the start of a
#: revolution changes by less than this (scaled state; the metal-contact default scene changed by 2e-4 over its
#: third revolution, the soft-contacts scene by 3e-10)
PERIODIC_TOL = 1e-5


def periodic(setup, sf, grid, knots_m, min_force, exclude):
    """Re-simulate from the scene's initial state until the revolution is periodic (see PERIODIC_TOL)."""
    return periodic_many(setup, sf, grid, [knots_m], min_force, exclude)[0]


def periodic_many(setup, sf, grid, knots_list, min_force, exclude) -> list:
    """:func:`periodic` for several schedules at once (:func:`.schedule.simulate_schedules`, on every core): those
    not yet periodic go on together, 2 revolutions at a time."""
    sims = simulate_schedules(setup, sf, grid, knots_list, min_force, exclude)
    done = setup.revolutions
    while done < 12:
        todo = [i for i, sim in enumerate(sims) if sim.change > PERIODIC_TOL]
        if not todo:
            break
        starts = []
        for i in todo:
            z = sims[i].z[:, -1].copy()
            z[setup.layout.counts] = 0.0  # event counts per revolution
            starts.append(z)
        again = simulate_schedules(setup, sf, grid, [knots_list[i] for i in todo], min_force, exclude, revolutions=2,
                                   z_starts=starts)
        for i, sim in zip(todo, again, strict=True):
            sims[i] = sim
        done += 2
    return sims
