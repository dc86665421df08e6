"""Names of the model's state and inputs, importable without sympy (derive.symbols builds its symbols from them)."""

from .submodels.seal import SealBody

#: the state x: the seal body's positions (x, y, phi) and their time derivatives, as it declares them (Eq. 10)
STATE_NAMES: tuple[str, ...] = tuple(s.name for s in SealBody.states)
#: the inputs u: chamber pressures on the leading and trailing side
INPUT_NAMES: tuple[str, ...] = ("Pa", "Pb")
