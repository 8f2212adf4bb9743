"""OpenCRG road surfaces: left/right tracks in and out.

Reading and writing go through ``pycrg`` (bindings of the ASAM OpenCRG C library,
optional dependency ``inerterlab[crg]``). A CRG file stores the elevation on a grid of
road co-ordinates: u along the reference line, v to the left of it. A track pair is
the elevation along u at v = +track/2 (left) and v = -track/2 (right), read with the
library's own interpolation; files written here are straight roads (heading 0) with
two long sections at those v and an empty modifier section, so a reader keeps the data
where it is.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import DataFileError, InerterlabError, ParameterError, check_positive

__all__ = ["read_crg_tracks", "write_crg_tracks", "read_crg_profile"]


def _pycrg():
    try:
        import pycrg
    except ImportError:  # pragma: no cover - depends on the environment
        raise InerterlabError(
            "reading OpenCRG files needs the optional package pycrg: pip install 'inerterlab[crg]'"
        ) from None
    return pycrg


def _check_crg_file(p: Path) -> None:
    """A regular file within the input size cap (the library reads it whole)."""
    from ..io import input_size_limit

    if not p.exists():
        raise DataFileError(p, "no such file")
    if not p.is_file():
        # the library opens the path itself: only a regular file has a size to check
        raise DataFileError(p, "is not a regular file; an OpenCRG road must be one")
    size, limit = p.stat().st_size, input_size_limit()
    if size > limit:
        raise DataFileError(p, f"is {size} bytes; a road file may have at most {limit} bytes here")


def _open(p: Path):
    pycrg = _pycrg()
    _check_crg_file(p)
    try:
        return pycrg.RoadSurface.open(str(p))
    except Exception as e:  # the library's load errors
        raise DataFileError(p, f"cannot read as OpenCRG: {_one_line(e)}") from None


def _one_line(e: Exception) -> str:
    return " ".join(str(e).split())[:300]


def _inside(p: Path, road, name: str, v: float) -> None:
    """Refuse a lateral position outside the file's data (no silent border values)."""
    v0, v1 = road.dataset.v_range()
    tol = 1e-9 * max(1.0, abs(v0), abs(v1))
    if not (v0 - tol <= v <= v1 + tol):
        raise ParameterError(
            name, v, f"a lateral position inside the file's range [{v0:g}, {v1:g}] m ({p.name})"
        )


def _grid(p: Path, u0: float, u1: float, h: float) -> np.ndarray:
    from ..resources import check_memory

    check_memory(3.0 * ((u1 - u0) / h + 1), what=f"samples of {p.name}", parameter="step")
    return np.arange(u0, u1 + 1e-9 * h, h)


def read_crg_tracks(path, track: float = 1.5, step: float | None = None):
    """(u [m], z_left [m], z_right [m]) of a CRG file, every ``step`` m along u.

    ``step`` defaults to the file's u increment. Elevations include the reference
    line's own elevation (slope), as the library evaluates them. Both wheels must lie
    inside the file's lateral range: a track wider than the road is refused, never read
    off the border.
    """
    p = Path(path)
    half = 0.5 * check_positive("track", track, "m")
    h = None if step is None else check_positive("step", step, "m")
    with _open(p) as road:
        try:
            _inside(p, road, "track", half)
            _inside(p, road, "track", -half)
        except ParameterError:
            v0, v1 = road.dataset.v_range()
            raise ParameterError(
                "track",
                track,
                f"a track within the lateral range [{v0:g}, {v1:g}] m of {p.name} "
                "(the wheels at +/- track/2)",
            ) from None
        try:
            u0, u1 = road.dataset.u_range()
            du = road.dataset.increments()[0]
            h = du if h is None else h
            u = _grid(p, u0, u1, h)
            zl = np.asarray(road.contact_point.uv_to_z_many(u, np.full_like(u, half)))
            zr = np.asarray(road.contact_point.uv_to_z_many(u, np.full_like(u, -half)))
        except InerterlabError:
            raise
        except Exception as e:  # the library's evaluation errors
            raise DataFileError(p, f"cannot read as OpenCRG: {_one_line(e)}") from None
    if not (np.all(np.isfinite(zl)) and np.all(np.isfinite(zr))):
        raise DataFileError(p, "the tracks cross cells without data (NaN)")
    return u - u[0], zl, zr


def read_crg_profile(path, step: float | None = None, lateral: float = 0.0):
    """(u [m], z [m]) along the long section at v = ``lateral`` [m] (0: the reference line).

    ``lateral`` must lie inside the file's lateral range (named in the error)."""
    from ..errors import check_finite

    lateral = check_finite("lateral", lateral)
    p = Path(path)
    h = None if step is None else check_positive("step", step, "m")
    with _open(p) as road:
        _inside(p, road, "lateral", lateral)
        try:
            u0, u1 = road.dataset.u_range()
            h = road.dataset.increments()[0] if h is None else h
            u = _grid(p, u0, u1, h)
            z = np.asarray(road.contact_point.uv_to_z_many(u, np.full_like(u, lateral)))
        except InerterlabError:
            raise
        except Exception as e:
            raise DataFileError(p, f"cannot read as OpenCRG: {_one_line(e)}") from None
    if not np.all(np.isfinite(z)):
        raise DataFileError(p, f"the long section at v = {lateral:g} m crosses cells without data")
    return u - u[0], z


def write_crg_tracks(
    path, x, z_left, z_right, track: float = 1.5, comment: str = "", fmt: str = "KDBI"
) -> Path:
    """Write a straight CRG road holding the two tracks (x evenly spaced, a multiple of 1 mm).

    ``fmt``: OpenCRG data format, "KDBI" (binary, double precision, the default here: a round
    trip through the library's evaluation is good to about 3e-10 m), "KRBI" (binary, single), "LDFI" or "LRFI" (ASCII).
    """
    from ..errors import check_choice

    pycrg = _pycrg()
    check_choice("fmt", fmt, ("KDBI", "KRBI", "LDFI", "LRFI"))
    x = np.asarray(x, dtype=float)
    zl = np.asarray(z_left, dtype=float)
    zr = np.asarray(z_right, dtype=float)
    if x.ndim != 1 or x.shape != zl.shape or x.shape != zr.shape or x.size < 2:
        raise ParameterError("x", f"arrays of shape {x.shape}", "three equal 1-D arrays")
    dx = np.diff(x)
    if np.any(dx <= 0) or not np.allclose(dx, dx[0], rtol=1e-9, atol=1e-12):
        raise ParameterError("x", "uneven samples", "evenly spaced distances")
    half = 0.5 * check_positive("track", track, "m")
    z = np.column_stack([zr, zl])  # v ascending: right (-) then left (+)
    pycrg.write(
        str(path),
        z,
        float(dx[0]),
        np.array([-half, half]),
        0.0,
        mods={},
        comment=comment,
        fmt=fmt,
    )
    return Path(path)
