"""The groove's contact cases of Algorithm 3 (Section 4.4), as plain names: the nine cases and the gaps that name
them. Imports nothing, so that the submodels' declaration checks (which refuse a mode label a case takes) read
them without the hybrid modes of :mod:`.modes`, which read the registry."""

from __future__ import annotations

#: the nine cases of Algorithm 3: name -> (b1 closed, b2 closed, b3 closed, b4 closed)
CASES: dict[str, tuple[bool, bool, bool, bool]] = {
    "q1": (True, False, False, True),
    "n3": (False, True, True, False),
    "p1": (True, False, False, False),
    "n2": (False, True, False, False),
    "p3": (False, False, True, False),
    "q2": (False, False, False, True),
    "q3": (False, False, True, True),
    "n1": (True, True, False, False),
    "p2": (False, False, False, False),
}


def case_of(closed_b1: bool, closed_b2: bool, closed_b3: bool, closed_b4: bool) -> str:
    """Algorithm 3: the case name for the closed groove contacts ('x?' outside the paper's nine)."""
    back = "n" if closed_b2 else "q" if closed_b4 else "p"
    front = "1" if closed_b1 else "3" if closed_b3 else "2"
    name = back + front
    if closed_b2 and closed_b4 or closed_b1 and closed_b3:
        # both back contacts at once is impossible (b2 + b4 = Wg - Ws cos(phi) > 0); both front contacts
        # only past |phi| ~ 11 deg for the case study: outside the paper's nine cases
        return "x" + name[1]
    return name


#: the groove's gaps b1..b4: the nine cases of Algorithm 3 name them together, and their smallest is the leakage
#: gap b_gap of Algorithm 4
GROOVE_GUARDS = ("b1", "b2", "b3", "b4")
