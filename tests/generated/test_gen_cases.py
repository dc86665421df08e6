"""Guards, case labels (Algorithm 3) and each case's right-hand side on states placed in each case."""

from __future__ import annotations

import numpy as np
import pytest

from apexseal.derive.modes import CASES, case_of
from apexseal.generated.layout import mode_label

OPEN, CLOSED = 3e-6, -1e-6  # target gaps (m)
#: case -> two groove gaps (index in b1..b4) to place; the other two must come out open
PLACED = {
    "q1": {0: CLOSED, 3: CLOSED}, "n3": {1: CLOSED, 2: CLOSED}, "p1": {0: CLOSED, 1: OPEN},
    "n2": {1: CLOSED, 0: OPEN}, "p3": {2: CLOSED, 3: OPEN}, "q2": {3: CLOSED, 2: OPEN},
    "q3": {2: CLOSED, 3: CLOSED}, "n1": {0: CLOSED, 1: CLOSED}, "p2": {0: OPEN, 1: 5 * OPEN},
}
#: (x position, housing label, spring label): x = 0 presses tip and spring; -1 um lifts the tip; 2.1 mm frees the spring
AXIAL = [(0.0, "h", "s"), (-1e-6, "h0", "s"), (2.1e-3, "h", "s0")]


def place(guards, p, u, theta, x_pos, targets, guard_names):
    """Newton on (y, phi) so that two groove gaps (index in b1..b4) take their target values."""
    z = np.zeros(2)
    idx = [guard_names.index(f"b{i + 1}") for i in targets]
    want = np.array(list(targets.values()))

    def gaps(z):
        return np.array(guards(theta, np.r_[x_pos, z[0], z[1], 0.0, 0.0, 0.0], p, u)).ravel()

    for _ in range(30):
        r = gaps(z)[idx] - want
        if np.abs(r).max() < 1e-13:
            break
        J = np.column_stack([(gaps(z + h)[idx] - gaps(z - h)[idx]) / 2e-9 for h in (np.r_[1e-9, 0], np.r_[0, 1e-9])])
        z = z - np.linalg.solve(J, r)
    return np.r_[x_pos, z[0], z[1], 0.0, 0.0, 0.0], gaps(z)


@pytest.mark.parametrize("case", list(CASES))
def test_states_placed_in_each_case(loaded, params, case):
    fns = loaded.c
    u = np.array([3e5, 1.5e5])
    for x_pos, h, s in AXIAL:
        names = list(fns.guard_names)
        x, g = place(fns.guards, params, u, 0.7, x_pos, PLACED[case], names)
        closed = g < 0
        groove = closed[[names.index(b) for b in ("b1", "b2", "b3", "b4")]]
        assert case_of(*groove) == case, (x_pos, g)
        assert tuple(groove) == CASES[case]
        assert (h == "h") == closed[names.index("xs5")] and (s == "s") == closed[names.index("spring")], g
        label = mode_label(loaded.sx.guard_names, closed)
        assert label == f"{case}_{h}_{s}"
        # the manifest's mode table and the compiled rhs with the mode's activations agree with Python
        index = [m["label"] for m in loaded.manifest.modes].index(label)
        assert loaded.manifest.modes[index]["closed"] == [int(c) for c in closed]
        want = np.array(fns.mode_rhs(label)(0.7, x, params, u)).ravel()
        np.testing.assert_allclose(np.array(fns.rhs_switched(0.7, x, params, u)).ravel(), want, rtol=1e-13)


def test_impossible_groove_pair_has_no_mode(loaded):
    names = list(loaded.sx.guard_names)
    closed = {"b1": -1e-6, "b2": -1e-6, "b3": 1e-6, "b4": -1e-6, "xs5": -1e-6, "spring": -1e-6}  # b2, b4 at once
    g = np.array([closed[n] for n in names])
    assert case_of(*(closed[b] < 0 for b in ("b1", "b2", "b3", "b4"))).startswith("x")
    assert all(m["closed"] != [int(c) for c in g < 0] for m in loaded.manifest.modes)


def test_header_indices_follow_the_names(loaded):
    text = (loaded.source_dir / "apexseal_model.h").read_text()
    for prefix, names in (("P", loaded.sx.parameter_names), ("X", loaded.sx.state_names),
                          ("G", loaded.sx.guard_names), ("Y", loaded.sx.output_names)):
        for i, name in enumerate(names):
            assert f"#define APEXSEAL_{prefix}_{name.upper()} {i}\n" in text
    for i, label in enumerate(loaded.sx.mode_labels):
        assert f"#define APEXSEAL_MODE_{label.upper()} {i}\n" in text
