"""The ``footfall`` command line.

Every command that computes something writes JSON and a figure into ``--out``. Input errors
(:class:`footfall.errors.FootfallError`) are printed as one clear line and exit with code 2.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import typer
from rich.console import Console

from footfall.errors import FootfallError, InputError

app = typer.Typer(
    name="footfall",
    help="Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
console = Console(stderr=True)


def parse_floats(field: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers, naming ``field`` on error."""
    try:
        return [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise InputError(field, text, "comma-separated numbers, e.g. 0,0.3,0.3") from None


def write_json(path: Path, payload: dict[str, Any]) -> None:
    """Write ``payload`` as indented JSON, creating parent folders."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(payload, indent=2) + "\n")


def main() -> None:
    """Entry point of the ``footfall`` console script."""
    try:
        app()
    except FootfallError as exc:
        console.print(f"[bold red]error:[/] {exc}")
        sys.exit(2)
