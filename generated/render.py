"""Render the C templates (``templates/*.in.*``) from the generation record.

Templates are real C files with an ``.in`` infix (acados' practice); the output
drops the infix (``apexseal_model.in.h`` -> ``apexseal_model.h``). Rendering is
strict (an unknown name is an error) and byte-deterministic: blocks are trimmed,
the template's trailing newline is kept and line endings are ``\\n``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import jinja2

from ..files import atomic_write
from .manifest import TEMPLATE_DIR, template_paths


def environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATE_DIR)),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        newline_sequence="\n",
        autoescape=False,
    )


def output_name(template_name: str) -> str:
    return template_name.replace(".in.", ".", 1)


def check_c_names(context: dict[str, Any]) -> None:
    """Upper-cased names become C macros: refuse two names that would collide."""
    for key in ("state", "parameters", "inputs", "guards", "outputs"):
        seen: dict[str, str] = {}
        for name in context[key]:
            macro = name.upper()
            if not macro.replace("_", "").isalnum():
                raise ValueError(f"{key} name {name!r} is not a C identifier")
            if macro in seen:
                raise ValueError(f"{key} names {seen[macro]!r} and {name!r} give the same C macro {macro}")
            seen[macro] = name


def render_all(context: dict[str, Any], out_dir: Path) -> list[str]:
    """Render every template into ``out_dir``; return the names of the files written."""
    check_c_names(context)
    env = environment()
    written = []
    for path in template_paths():
        text = env.get_template(path.name).render(**context)
        name = output_name(path.name)
        atomic_write(Path(out_dir) / name, text)
        written.append(name)
    return written
