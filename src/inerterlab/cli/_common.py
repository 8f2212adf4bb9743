"""Helpers shared by the command modules: JSON output, tables, atomic files."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SEED_MAX, InerterlabError, ParameterError, check_seed
from ..io import atomic_path
from ..io import atomic_write_text as atomic_write_text


def _clean(obj: Any, where: str = "") -> Any:
    if isinstance(obj, dict):
        return {str(k): _clean(v, f"{where}.{k}" if where else str(k)) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist(), where)
    if isinstance(obj, np.generic):
        return _clean(obj.item(), where)
    if isinstance(obj, float) and not math.isfinite(obj):
        raise InerterlabError(
            f"result {where or 'value'} is {obj} (not a finite number): the computation "
            "left the range of floating point numbers for these inputs; nothing was printed"
        )
    return obj


def emit_json(obj: Any) -> None:
    """Print ``obj`` as one JSON object; refuses NaN and infinities."""
    sys.stdout.write(json.dumps(_clean(obj), allow_nan=False) + "\n")


def atomic_savefig(fig: Any, path: str | os.PathLike, option: str = "--plot") -> Path:
    """Save a matplotlib figure atomically (format from the suffix, PNG without one)."""
    suffix = Path(path).suffix.lstrip(".").lower() or "png"
    formats = fig.canvas.get_supported_filetypes()
    if suffix not in formats:
        raise ParameterError(
            option, str(path), "a figure file ending in ." + ", .".join(sorted(formats))
        )
    with atomic_path(path, suffix="." + suffix, option=option) as tmp:
        fig.savefig(tmp, format=suffix, dpi=120, bbox_inches="tight")
    return Path(path)


def print_table(title: str, rows: list[tuple[str, str]]) -> None:
    """Readable two-column table on standard output."""
    from rich.console import Console
    from rich.table import Table
    from rich.text import Text

    # plain Text, not console markup: "[kg]" and "[m/s^2]" are units, not style tags
    t = Table(title=Text(title))
    t.add_column("quantity")
    t.add_column("value", justify="right")
    for k, v in rows:
        t.add_row(Text(str(k)), Text(str(v)))
    Console().print(t)


def _seed_callback(ctx: Any, param: Any, value: Any) -> Any:
    if value is None:
        return value
    return check_seed(param.opts[0].lstrip("-"), value)


def seed_option(help_text: str, *names: str) -> Any:
    """The one definition of every random seed option: an integer 0 ... 2**32 - 1."""
    import typer

    return typer.Option(*names, help=f"{help_text} (0-{SEED_MAX})", callback=_seed_callback)


def parse_float(name: str, text: str) -> float:
    """Parse a CLI number, raising a ParameterError naming the option."""
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise ParameterError(name, text, "a finite number") from None
    if not math.isfinite(x):
        raise ParameterError(name, text, "a finite number")
    return x
