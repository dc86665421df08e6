"""Names of the model's state and inputs, importable without sympy (derive.symbols builds its symbols from them)."""

#: the state x: positions (x, y, phi) and their time derivatives
STATE_NAMES: tuple[str, ...] = ("x", "y", "phi", "xd", "yd", "phid")
#: the inputs u: chamber pressures on the leading and trailing side
INPUT_NAMES: tuple[str, ...] = ("Pa", "Pb")
