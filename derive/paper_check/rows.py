"""One row per printed equation: its status (agrees, differs, structural, assumption), how it was checked, and for
a difference the verified difference, the reason and a numeric example."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import sympy as sp

from .. import modes, paper
from ..kinematics import plain
from ..symbols import P
from .counterparts import Derived, cached_derived, difference
from .evaluation import evaluate, example_point, numeric_equal, prepare, resolve, show, symbolic_zero
from .findings import FINDINGS, NOTES, Finding
from .values import DEFAULTS, EXAMPLE_STATE, N_SAMPLES, REL_TOL, SETTINGS, fmt, fmt_vec, phi


@dataclass(frozen=True)
class Row:
    """One checked equation."""

    label: str
    title: str
    status: str  # agrees | differs | structural | assumption
    method: str  # how it was checked
    printed: str  # the print (transcribed)
    derived: str  # the derived counterpart, or the implementing function
    difference: str = ""  # printed - derived (verified), for differences and assumptions
    reason: str = ""
    example: str = ""
    model_uses: str = ""
    kind: str = ""  # for differences: "physics" or "typesetting"
    reading: str = ""
    alternative: str = ""
    alternative_status: str = ""  # does the alternative reading agree with the derivation?
    note: str = ""
    difference_verified: bool = True


def _compare(p: paper.Printed, d: Derived) -> Row:
    finding = FINDINGS().get(p.label)
    note = NOTES.get(p.label, "")
    base = dict(label=p.label, title=p.title, printed=p.text, reading=p.reading, alternative=p.alternative)
    if not p.printed:  # structural rows, and assumptions with nothing printed to compare
        ok = resolve(p.implemented_by)
        method = f"implemented by {p.implemented_by}" + ("" if ok else " (NOT FOUND)")
        note = (note + " " + _structural_extra(p.label)).strip()
        status = "structural" if p.kind == paper.STRUCTURAL else "assumption"
        return Row(status=status, method=method, derived=p.implemented_by, note=note, kind=finding.kind if finding else "",
                   reason=finding.reason if finding else "", model_uses=finding.model_uses if finding else "", **base)
    settings = SETTINGS.get(p.label, ("one", "sign"))
    derived = tuple(prepare(e, d, settings, p.free) for e in d.counterpart(p.label))
    printed = tuple(prepare(e, d, settings, p.free) for e in p.printed)
    equal, err = numeric_equal(printed, derived, p.label)
    symbolic = equal and symbolic_zero(difference(printed, derived))
    if symbolic:
        method = "symbolic (the difference simplifies to 0)"
    elif equal:
        method = f"numeric ({N_SAMPLES} random states, equal to {REL_TOL:g})"
    else:
        method = f"numeric ({N_SAMPLES} random states, max rel. diff {err:.0e})"
    status = "assumption" if p.kind == paper.ASSUMPTION else "agrees" if equal else "differs"
    alt_status = ""
    if p.alternative_printed:
        alt = tuple(prepare(e, d, settings, p.free) for e in p.alternative_printed)
        alt_equal = numeric_equal(alt, derived, p.label)[0]
        alt_status = "agrees" if alt_equal else "differs"
    if p.label == "A3":
        note = (note + " " + _case_completeness(d)).strip()
    if status == "differs":
        note = (f"See Errata ({finding.kind})." if finding else "UNEXPLAINED.") + (" " + note if note else "")
    row = Row(status=status, method=method, derived=_derived_text(derived), alternative_status=alt_status, note=note,
              **base)
    return row if status == "agrees" else _explain(row, p, finding, printed, derived, settings)


def _derived_text(derived: tuple[sp.Expr, ...]) -> str:
    text = show(derived)
    return text if len(text) <= 300 else f"(an expression of {sum(sp.count_ops(e) for e in derived)} operations)"


def _explain(row: Row, p: paper.Printed, f: Finding | None, printed: tuple, derived: tuple, settings) -> Row:
    """Difference (verified), reason and numeric example of a row that does not agree."""
    if f is None:
        return replace(row, reason="UNEXPLAINED difference", difference_verified=False)
    verified = True
    if f.difference:
        claimed = tuple(prepare(e, cached_derived(), settings, p.free) for e in f.difference)
        verified = numeric_equal(difference(printed, derived), claimed, p.label, ref=printed + derived)[0]
    pt = example_point(f.example)
    used = {s.name for e in printed + derived for s in e.free_symbols}
    values = evaluate(printed + derived, [pt])[0]
    vp, vd = values[:len(printed)], values[len(printed):]
    shown = EXAMPLE_STATE | f.example
    state = ", ".join(f"{k} = {fmt(v)}" for k, v in shown.items() if k in used or k in f.example)
    example = f"at {state or 'the defaults'}: printed {fmt_vec(vp)}, derived {fmt_vec(vd)}"
    return replace(row, difference=f.difference_text, reason=f.reason, example=example, model_uses=f.model_uses,
                   kind=f.kind, difference_verified=verified)


def _case_completeness(d: Derived) -> str:
    """The nine cases are all there are: both back contacts, or both front ones, cannot close at once."""
    gaps = {n: plain(d.g.gaps[n]) for n in ("b1", "b2", "b3", "b4")}
    back = sp.simplify(gaps["b2"] + gaps["b4"] - (P["Wg"] - P["Ws"] * sp.cos(phi))) == 0
    front = sp.simplify(gaps["b1"] + gaps["b3"] - (P["Wg"] * sp.cos(phi) - P["Ws"])) == 0
    limit = math.degrees(math.acos(DEFAULTS["Ws"] / DEFAULTS["Wg"]))
    same = {n: tuple(int(c) for c in v) for n, v in modes.CASES.items()} == paper.CASES
    modes_text = f" derive/modes.py CASES {'equals' if same else 'DIFFERS FROM'} the printed table."
    return (f"Verified: b2 + b4 = Wg − Ws cos ϕ ({'yes' if back else 'NO'}) > 0, so both back contacts never close at "
            f"once; b1 + b3 = Wg cos ϕ − Ws ({'yes' if front else 'NO'}) > 0 for |ϕ| < acos(Ws/Wg) = "
            f"{fmt(limit)}° (defaults), so both front contacts need a larger tilt: the nine cases are complete."
            + modes_text)


def _structural_extra(label: str) -> str:
    """Behavioural spot checks of the structural rows that have one."""
    if label == "A4":
        ok = modes.gap_width([1e-6, 2e-6, 3e-6, 4e-6]) == 1e-6 and modes.gap_width([-1e-9, 2e-6, 3e-6, 4e-6]) == 0.0
        return "Spot check: gap_width(1, 2, 3, 4 µm) = 1 µm, 0 with a contact closed: " + ("passed." if ok else "FAILED.")
    return ""


@functools.lru_cache(maxsize=1)
def check_rows() -> tuple[Row, ...]:
    """Every printed equation compared with the derivation, in the paper's order."""
    d = cached_derived()
    return tuple(_compare(p, d) for p in paper.equations())
