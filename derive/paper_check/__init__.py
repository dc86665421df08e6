"""Check every printed equation of the paper (derive/paper.py) against the derivation.

For each row the printed form, with the paper's intermediates (ao, l1, b6, ...)
replaced by their derived values, is compared with the derived counterpart built
from the derivation's own building blocks (kinematics, contact geometry, force
models, the derived model): :mod:`.counterparts`. The comparison
(:mod:`.evaluation`) is numerical at random states and parameters around the
default scene's values (the paper's case study, Section 4.5; fixed seed;
:mod:`.values`), and symbolic (expand, expand_trig, cancel, and ``sp.simplify``
for small ones) where that settles the difference; rows whose expressions are
too large stay numeric. Friction signs tanh(v/v_eps) are compared in their limit
sign(v).

A row (:mod:`.rows`) is "agrees", "differs", "structural" (a definition the
derivation implements; the implementing function is resolved) or "assumption"
(a modelling choice, see derive/assumptions.py). Every difference has a verified
symbolic difference, a physical reason and a numeric example
(:mod:`.findings`); the model always uses the derivation. :func:`write_report`
writes docs/paper-check.md, deterministically (:mod:`.report`).
"""

from .report import STATUSES, main_check, report_text, write_report
from .rows import Row, check_rows

__all__ = ["STATUSES", "Row", "check_rows", "main_check", "report_text", "write_report"]
