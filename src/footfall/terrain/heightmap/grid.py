"""Height maps: a grid of heights, reading it from a file, and rasterising a scene into one.

Convention for every format: cell ``heights[i, j]`` is the height [m] of the terrain at
``x = origin[0] + j * resolution``, ``y = origin[1] + i * resolution`` (rows run along y, columns
along x; a PNG's first row is the row at ``y = origin[1]``). Unknown cells are NaN.

No file can run code: ``.npy``/``.npz`` are read with ``allow_pickle=False``, a PNG with Pillow,
a CSV as plain numbers. Sizes are checked from the file header before the data is read.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import finite_vector, positive
from footfall.errors import InputError
from footfall.terrain.scene import Scene

#: most cells of a map (a 4000 x 4000 grid, 128 MB of float64): more is refused before reading
MAX_CELLS = 16_000_000
#: fewest rows and columns (the local plane fit needs a 3 x 3 neighbourhood)
MIN_SIDE = 3
#: largest |height| [m] accepted: larger values are a unit mistake (mm given as m) or garbage
MAX_ABS_HEIGHT = 10_000.0
#: largest CSV file read [bytes]
MAX_CSV_BYTES = 256 * 1024 * 1024
#: the PNG modes Pillow gives a 16-bit greyscale image
_PNG16_MODES = ("I;16", "I;16B", "I;16L", "I;16N")


@dataclass(frozen=True, eq=False)
class HeightMap:
    """A regular grid of terrain heights.

    Attributes:
        heights: (H, W) [m], float64, NaN where unknown; ``heights[i, j]`` is at
            ``origin + (j, i) * resolution``.
        resolution: cell size r [m] (square cells).
        origin: ``(x, y)`` (2,) [m] of the centre of cell ``[0, 0]``.

    Construction checks the shape (at least 3 x 3, at most ``MAX_CELLS`` cells), the dtype (real
    floating point), the values (finite or NaN, |z| <= ``MAX_ABS_HEIGHT``), that some cells are
    known and that the map is not one constant value everywhere (a blank sensor output).
    """

    heights: FloatArray
    resolution: float
    origin: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "resolution", positive("resolution", self.resolution))
        o = finite_vector("origin", self.origin, 2)
        o.setflags(write=False)
        object.__setattr__(self, "origin", o)
        h = check_heights(self.heights)
        h.setflags(write=False)
        object.__setattr__(self, "heights", h)

    @property
    def shape(self) -> tuple[int, int]:
        """``(H, W)``: rows (along y) and columns (along x)."""
        return (int(self.heights.shape[0]), int(self.heights.shape[1]))

    def cell_centres(self) -> tuple[FloatArray, FloatArray]:
        """``(X, Y)``, each (H, W) [m]: the coordinates of every cell centre."""
        h, w = self.shape
        xs = self.origin[0] + self.resolution * np.arange(w)
        ys = self.origin[1] + self.resolution * np.arange(h)
        return np.meshgrid(xs, ys)


def _check_shape(shape: tuple[int, ...], what: str = "heights") -> None:
    if len(shape) != 2:
        raise InputError(what, f"an array of shape {shape}", "a 2-D grid of heights (H, W)")
    if min(shape) < MIN_SIDE:
        raise InputError(
            what, f"a {shape[0]} x {shape[1]} grid", f"at least {MIN_SIDE} x {MIN_SIDE} cells"
        )
    if shape[0] * shape[1] > MAX_CELLS:
        raise InputError(
            what,
            f"a {shape[0]} x {shape[1]} grid ({shape[0] * shape[1]} cells)",
            f"at most {MAX_CELLS} cells (crop or downsample the map)",
        )


def _check_dtype(dtype: np.dtype, what: str = "heights") -> None:
    if dtype.kind != "f":
        hint = ""
        if dtype.kind in "iu":
            hint = (
                " (integer counts need a scale: save them as a 16-bit PNG and give --height-scale)"
            )
        raise InputError(what, f"dtype {dtype}", f"real floating-point heights in metres{hint}")


def check_heights(heights: object) -> FloatArray:
    """``heights`` as a float64 (H, W) array after the checks of :class:`HeightMap`."""
    if not isinstance(heights, np.ndarray):
        raise InputError("heights", type(heights).__name__, "a numpy array (H, W) of heights [m]")
    _check_shape(heights.shape)
    _check_dtype(heights.dtype)
    h = np.array(heights, dtype=np.float64)
    if np.isinf(h).any():
        i, j = np.argwhere(np.isinf(h))[0]
        raise InputError(f"heights[{i}, {j}]", float(h[i, j]), "finite heights, or NaN for unknown")
    known = ~np.isnan(h)
    if not known.any():
        raise InputError("heights", f"all {h.size} cells unknown (NaN)", "some known heights")
    big = known & (np.abs(np.where(known, h, 0.0)) > MAX_ABS_HEIGHT)
    if big.any():
        i, j = np.argwhere(big)[0]
        raise InputError(
            f"heights[{i}, {j}]",
            float(h[i, j]),
            f"|height| <= {MAX_ABS_HEIGHT:g} m (heights are in metres)",
        )
    vals = h[known]
    if known.all() and np.all(vals == vals[0]):
        raise InputError(
            "heights",
            f"every cell exactly {vals[0]:g} m",
            "a map with varying heights or unknown (NaN) cells around the terrain: a constant "
            "grid is what a blank or unfilled sensor map looks like",
        )
    return h


# ============================================================================= reading files
def _npy_header(fp: object, what: str) -> tuple[tuple[int, ...], np.dtype]:
    fmt = np.lib.format
    try:
        version = fmt.read_magic(fp)  # type: ignore[arg-type]
        if version == (1, 0):
            shape, _, dtype = fmt.read_array_header_1_0(fp)  # type: ignore[arg-type]
        else:
            shape, _, dtype = fmt.read_array_header_2_0(fp)  # type: ignore[arg-type]
    except (ValueError, OSError, EOFError) as e:
        raise InputError(what, "an unreadable array header", f"a .npy array ({e})") from None
    return tuple(shape), np.dtype(dtype)


def _read_npy(path: Path) -> FloatArray:
    with path.open("rb") as fp:
        shape, dtype = _npy_header(fp, "map")
    _check_shape(shape, "map")
    _check_dtype(dtype, "map")
    try:
        return np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError) as e:
        raise InputError("map", str(path), f"a readable .npy array of heights ({e})") from None


def _read_npz(path: Path, key: str | None) -> FloatArray:
    try:
        with zipfile.ZipFile(path) as zf:
            names = [n[:-4] for n in zf.namelist() if n.endswith(".npy")]
            if key is None:
                if len(names) != 1:
                    raise InputError(
                        "map",
                        f"{path.name} with arrays {names}",
                        "exactly one array, or --key NAME",
                    )
                key = names[0]
            if key not in names:
                raise InputError("key", key, f"one of the arrays in {path.name}: {names}")
            with zf.open(key + ".npy") as fp:
                shape, dtype = _npy_header(fp, f"map[{key}]")
            _check_shape(shape, f"map[{key}]")
            _check_dtype(dtype, f"map[{key}]")
        with np.load(path, allow_pickle=False) as npz:
            return np.asarray(npz[key])
    except (zipfile.BadZipFile, ValueError, OSError, EOFError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError("map", str(path), f"a readable .npz archive ({e})") from None


def _read_png(
    path: Path, height_scale: float | None, height_offset: float, nodata: int | None
) -> FloatArray:
    from PIL import Image, UnidentifiedImageError

    if height_scale is None:
        raise InputError(
            "height_scale", None, "metres per count for a 16-bit PNG (e.g. --height-scale 0.001)"
        )
    scale = positive("height_scale", height_scale)
    try:
        with Image.open(path) as im:
            w, h = im.size
            _check_shape((h, w), "map")
            if im.mode not in _PNG16_MODES:
                raise InputError("map", f"a PNG in mode {im.mode}", "a 16-bit greyscale PNG")
            counts = np.array(im, dtype=np.int64)
    except (UnidentifiedImageError, Image.DecompressionBombError, OSError, SyntaxError) as e:
        raise InputError("map", str(path), f"a readable 16-bit PNG ({e})") from None
    z = counts.astype(np.float64) * scale + height_offset
    if nodata is not None:
        z[counts == nodata] = np.nan
    return z


def _read_csv(path: Path) -> FloatArray:
    size = path.stat().st_size
    if size > MAX_CSV_BYTES:
        raise InputError(
            "map", f"{path.name} of {size} bytes", f"a CSV of at most {MAX_CSV_BYTES} bytes"
        )
    text = path.read_text(errors="replace")
    rows = [
        line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")
    ]
    out: list[list[float]] = []
    for k, line in enumerate(rows):
        try:
            out.append([float(v) if v.strip() else np.nan for v in line.split(",")])
        except ValueError:
            raise InputError(
                f"map line {k + 1}", line[:80], "comma-separated numbers (empty or nan: unknown)"
            ) from None
    widths = {len(r) for r in out}
    if len(widths) > 1:
        raise InputError(
            "map", f"rows of {sorted(widths)} values", "the same number of values per row"
        )
    arr = np.array(out, dtype=np.float64)
    if arr.ndim != 2:
        raise InputError("map", str(path), "a non-empty CSV grid of heights")
    return arr


def load_heightmap(
    path: str | Path,
    resolution: float,
    origin: tuple[float, float] = (0.0, 0.0),
    *,
    key: str | None = None,
    height_scale: float | None = None,
    height_offset: float = 0.0,
    nodata: int | None = None,
) -> HeightMap:
    """Read a height map from ``.npy``, ``.npz``, a 16-bit ``.png`` or ``.csv``.

    Args:
        path: the file; its suffix chooses the format.
        resolution: cell size [m].
        origin: ``(x, y)`` [m] of the centre of the first cell ``[0, 0]``.
        key: the array to take from an ``.npz`` holding several.
        height_scale: PNG only, required: metres per count (height = count * scale + offset).
        height_offset: PNG only: height [m] of count 0.
        nodata: PNG only: the count that marks an unknown cell (NaN).

    Raises:
        InputError: naming the field, for an unreadable file, a wrong format, dtype or size.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError("map", str(p), "an existing file (.npy, .npz, .png or .csv)")
    suffix = p.suffix.lower()
    if suffix == ".npy":
        arr = _read_npy(p)
    elif suffix == ".npz":
        arr = _read_npz(p, key)
    elif suffix == ".png":
        arr = _read_png(p, height_scale, float(height_offset), nodata)
    elif suffix == ".csv":
        arr = _read_csv(p)
    else:
        raise InputError("map", p.name, "a .npy, .npz, .png (16-bit) or .csv file")
    if suffix != ".png" and (height_scale is not None or nodata is not None):
        raise InputError("height_scale", height_scale, "no scale or nodata except for a 16-bit PNG")
    return HeightMap(arr, resolution, np.asarray(origin, dtype=float))


# ============================================================================= scene -> map
def rasterize_scene(
    scene: Scene, resolution: float, *, pad: float = 0.1, fill: float = np.nan
) -> HeightMap:
    """The height map an ideal sensor would see of ``scene``'s regions (no noise).

    Each cell takes the height of the highest region containing its centre (regions sharing an
    edge agree there), ``fill`` where none does. The grid spans the regions' bounding box plus
    ``pad`` on every side; cell edges (not centres) fall on ``min - pad + k * resolution``, so a
    region edge on that lattice never passes through a cell centre (the known cells then add up
    to the regions' area exactly).

    Args:
        scene: the scene.
        resolution: cell size [m].
        pad: margin around the regions [m].
        fill: height of cells on no region [m] (default NaN: unknown).
    """
    res = positive("resolution", resolution)
    if not (np.isnan(fill) or np.isfinite(fill)):
        raise InputError("fill", fill, "a finite height or NaN")
    lo, hi = scene.terrain.bounds()
    pad = float(pad)
    origin = lo[:2] - pad + res / 2
    w = int(np.ceil((hi[0] - lo[0] + 2 * pad) / res))
    h = int(np.ceil((hi[1] - lo[1] + 2 * pad) / res))
    _check_shape((h, w))
    xs = origin[0] + res * np.arange(w)
    ys = origin[1] + res * np.arange(h)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.column_stack([gx.ravel(), gy.ravel()])
    z = np.full(pts.shape[0], -np.inf)
    for region in scene.terrain:
        a, b = region.halfspaces()
        inside = np.all(pts @ a.T <= b + 1e-12, axis=1)
        z[inside] = np.maximum(z[inside], region.height_at(pts[inside]))
    z[np.isinf(z)] = fill
    return HeightMap(z.reshape(h, w), res, origin)
