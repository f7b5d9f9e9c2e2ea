"""What every ``footfall`` command shares: the app, the console, option conventions and checks."""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from rich.console import Console
from rich.text import Text

from footfall.errors import InputError

if TYPE_CHECKING:
    from footfall.sim.disturbance import Disturbance

app = typer.Typer(
    name="footfall",
    help="Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    # help texts are plain text: units like [s] and extras like footfall[robots] must show as typed
    rich_markup_mode=None,
)
#: user-facing messages (scene names, paths, install hints) are printed as typed, never as markup
console = Console(stderr=True, markup=False, highlight=False, soft_wrap=True)


def _say_error(prefix: str, message: str) -> None:
    """Print ``prefix: message`` on stderr, the prefix in bold red, the message as plain text."""
    console.print(Text(f"{prefix}: ", style="bold red") + Text(message))


@app.callback()
def _root() -> None:
    """Footstep planning for legged robots (LIP/ALIP, MIQCQP planner, quadruped ZMP gaits)."""


_THREADS_HELP = (
    "Worker processes of the bnb backend / solver threads (default: 2, or the cores if fewer; "
    "at most the cores this process may use)."
)


def _threads(threads: int | None) -> int:
    """``--threads``: as given, or the default of two workers where two cores exist."""
    if threads is not None:
        return threads
    from footfall.planning.plan import available_cores

    return min(2, available_cores())


#: folders :func:`output_folder` created in this process, the deepest last
_CREATED: list[Path] = []


def output_folder(out: Path) -> Path:
    """Create ``out`` (and its parents) and check that it is a writable folder, before any work
    whose result would otherwise be lost. The folders it creates are remembered, so that a run
    that fails before writing into them leaves none behind (:func:`remove_unused_folders`)."""
    missing = [p for p in (out, *out.parents) if not p.exists()]
    try:
        out.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise InputError("out", str(out), "a folder (a file of that name exists)") from None
    except OSError as e:
        raise InputError("out", str(out), f"a folder that can be created ({e.strerror})") from None
    finally:
        _CREATED.extend(p for p in reversed(missing) if p.is_dir())
    if not out.is_dir():
        raise InputError("out", str(out), "a folder (a file of that name exists)")
    if not os.access(out, os.W_OK | os.X_OK):
        raise InputError("out", str(out), "a folder this user may write to")
    return out


def remove_unused_folders() -> None:
    """Remove the folders :func:`output_folder` created that are still empty, deepest first
    (called when a command fails: bad input found after ``--out`` was made must not leave an
    empty folder). A folder with anything in it, or one that existed before, is left alone."""
    while _CREATED:
        folder = _CREATED.pop()
        try:
            folder.rmdir()  # only an empty folder can be removed
        except OSError:
            pass


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` name one file (the same inode when ``b`` exists: links and
    symlinks included; the same resolved path when it does not)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def refuse_inputs_as_outputs(
    inputs: Sequence[str | Path | None], outputs: Mapping[str, Iterable[Path]]
) -> None:
    """Refuse, before any work, an output path that is one of the command's input files.

    Args:
        inputs: the files the command reads (a string that names no existing file, such as a
            built-in scene name, and None are skipped).
        outputs: per option (``"out"``, ``"log_json"``), the files the command will write.

    Raises:
        InputError: naming the option, the output path and the input it would replace.
    """
    files = [Path(i) for i in inputs if i is not None and Path(i).is_file()]
    for field, paths in outputs.items():
        for path in paths:
            for source in files:
                if _same_file(source, Path(path)):
                    raise InputError(
                        field,
                        str(path),
                        f"a path that is not an input of this command (it would replace {source})",
                    )


def parse_floats(field: str, text: str) -> list[float]:
    """Parse a comma-separated list of numbers, naming ``field`` on error."""
    try:
        return [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise InputError(field, text, "comma-separated numbers, e.g. 0,0.3,0.3") from None


@contextmanager
def _progress_bar() -> Iterator[Callable[[str, int, int], None]]:
    """A console progress bar; yields ``progress(what, done, total)`` (total 0: unknown)."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn())
    with Progress(*columns, TimeElapsedColumn(), console=console) as bar:
        task = bar.add_task("planning", total=None)

        def progress(what: str, done: int, total: int) -> None:
            bar.update(task, description=what, completed=done, total=total or None)

        yield progress


def _list_arg(text: str) -> list[str]:
    """The non-empty items of a comma-separated option."""
    return [item.strip() for item in text.split(",") if item.strip()]


def _positive_int(field: str, value: int) -> int:
    if value < 1:
        raise InputError(field, value, "an integer >= 1")
    return value


#: help of ``--heading-windows`` (plan, walk)
HEADING_WINDOWS_HELP = (
    "Beyond the document: when the MIQCQP solve ends at its time limit without a plan, search "
    "for as long again with every heading pinned to the start-goal band except at 2 W + 1 "
    "consecutive footsteps (W = this value, doubled while no window has a plan); 0: no search."
)

#: help of ``--robot``
ROBOT_HELP = (
    "The robot: biped (footfall's 30 kg biped), g1 or talos (robot files of models in "
    "example-robot-data: pip install 'footfall[robots]'), or your robot file (.yaml, see "
    "footfall robot inspect). The plan is made for its measured mass, CoM height and feet and "
    "the reach, step height and timing derived from its legs."
)


# --- pushes: one disturbance type for every command (footfall.sim.disturbance) ---
#: ``--push`` [N s]
PushOption = Annotated[
    float,
    typer.Option(
        "--push",
        help="Push impulse [N s] (0: none): one horizontal push on the body lasting "
        "--push-duration, whose direction, step and phase of single support are drawn from --seed "
        "unless given.",
    ),
]
#: ``--push-dv`` [m/s]
PushDvOption = Annotated[
    float | None,
    typer.Option(
        "--push-dv",
        help="The push as a velocity change [m/s] instead of --push: impulse = robot mass x "
        "velocity change.",
    ),
]
#: ``--seed``
SeedOption = Annotated[
    int,
    typer.Option(
        "--seed",
        help="Seed of the push's direction, step and phase (the same draw for a seed in footfall "
        "walk, simulate, compare and study) and of any estimate noise.",
    ),
]
#: ``--push-step``, ``--push-phase``, ``--push-direction`` [deg], ``--push-duration`` [s]
PushStepOption = Annotated[
    int | None,
    typer.Option(
        "--push-step", help="Single support the push comes in (0-based). [default: drawn]"
    ),
]
PushPhaseOption = Annotated[
    float | None,
    typer.Option(
        "--push-phase",
        help="When in that single support, as a share of it in [0, 1]. [default: drawn]",
    ),
]
PushDirectionOption = Annotated[
    float | None,
    typer.Option(
        "--push-direction",
        help="Push direction in the world frame [deg] (0 = +x, 90 = +y). [default: drawn]",
    ),
]
PushDurationOption = Annotated[float, typer.Option("--push-duration", help="Push length [s].")]


def disturbance_of(
    push: float,
    push_dv: float | None,
    seed: int,
    step: int | None,
    phase: float | None,
    direction_deg: float | None,
    duration: float,
) -> Disturbance:
    """The :class:`~footfall.sim.disturbance.Disturbance` of a command's push options: the
    seed's draw (:meth:`Disturbance.of_seed`) with the given step, phase and direction."""
    from dataclasses import replace

    from footfall._validate import finite
    from footfall.sim.disturbance import Disturbance

    given: dict[str, object] = {}
    if step is not None:
        given["step"] = step
    if phase is not None:
        given["phase"] = phase
    if direction_deg is not None:
        given["direction"] = math.radians(finite("--push-direction [deg]", direction_deg))
    d = Disturbance.of_seed(seed, impulse=push, dv=push_dv, duration=duration)
    return replace(d, **given)  # type: ignore[arg-type]
