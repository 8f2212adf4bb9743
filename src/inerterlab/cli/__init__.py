"""The ``inerterlab`` command line: a thin layer over the public functions.

Each command lives in its own module of this package and registers itself on the
shared Typer ``app`` through a ``register(app)`` function listed in ``_COMMANDS``.
User errors print one line on standard error and exit with status 2; unexpected
errors exit with status 1 and a hint to rerun with ``--debug`` for the traceback.
"""

from __future__ import annotations

import errno
import importlib
import os
import sys
import warnings

import typer
from numba.core import event as _nb_event

try:  # typer >= 0.20 vendors its own copy of click
    from typer._click import exceptions as _cx
except ImportError:  # pragma: no cover - older typer on plain click
    from click import exceptions as _cx

from .._numba_cache import FIRST_CLASS_WARNING
from ..errors import InerterlabError, Interrupted, one_line

app = typer.Typer(
    name="inerterlab",
    help="Adaptive-flywheel inerters and the suspensions that use them. "
    "SI units throughout; frequencies in Hz where the option name says so.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _print_version(value: bool) -> None:
    if value:
        from .. import __version__

        typer.echo(f"inerterlab {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False,
        "--version",
        help="Print the version and exit.",
        callback=_print_version,
        is_eager=True,
    ),
) -> None:
    """Adaptive-flywheel inerters and the suspensions that use them."""


# modules of this package that define ``register(app)``; one line per command group
_COMMANDS = [
    "frequency",
    "flywheel",
    "reproduce",
    "studies",
    "devices",
    "identify",
    "simulate",
    "vehicle",
    "network",
    "design",
]

for _name in _COMMANDS:
    importlib.import_module(f"{__name__}.{_name}").register(app)


_INTERRUPTED = (
    "inerterlab: interrupted; results already written are kept "
    "(rerun the same command to resume where it applies)"
)


def _say(text: str) -> None:
    """Print one error line on standard error: folded and shortened (one_line)."""
    print(one_line(text), file=sys.stderr)


def _usage_message(e: Exception) -> str:
    msg = e.format_message()
    param = getattr(e, "param", None)
    if isinstance(e, _cx.BadParameter) and param is not None:
        opts = "/".join(getattr(param, "opts", []) or [str(param.name)])
        value = None
        cause = e.__cause__
        errors = getattr(cause, "errors", None)
        if callable(errors):
            try:
                value = errors()[0].get("input")
            except Exception:  # noqa: BLE001
                value = None
        got = f" got {value!r};" if value is not None else ""
        return f"invalid value for {opts}:{got} {msg}"
    return msg


def _os_error_message(e: OSError) -> str:
    """One line for a failure of the system (full disk, read-only mount, permission)."""
    what = e.filename if e.filename is not None else ""
    reason = e.strerror or str(e)
    hint = {
        errno.ENOSPC: "free some space or write elsewhere",
        errno.EDQUOT: "free some space or write elsewhere",
        errno.EROFS: "the file system is mounted read-only; write elsewhere",
        errno.EACCES: "check the permissions or write elsewhere",
        errno.EPERM: "check the permissions or write elsewhere",
    }.get(e.errno, "")
    return f"{what + ': ' if what else ''}{reason}{' (' + hint + ')' if hint else ''}"


#: the line a terminal sees while the package's numerical code compiles
COMPILE_NOTICE = (
    "inerterlab: compiling the numerical code (once per install and model structure, "
    "one to two minutes; later runs load it) ..."
)


class CompileNotice(_nb_event.Listener):
    """One line on standard error when numba starts compiling the package's code in this
    run (its first run after an install: 58-105 s of one core's time for a quarter car's
    simulation or a device rig on the development machine, decisions.md stops 68, 72
    and 73), during which
    the command would otherwise say nothing. numba reports a compilation only where its
    cache has no machine code for the function (``numba:compile`` events): a run that
    loads the code prints nothing. Only on a terminal: output piped to a file or a
    program is left as the command writes it. ``stream``: where to write (standard error
    as it is at the time, by default)."""

    def __init__(self, stream=None):
        self.stream = stream
        self.said = False

    def on_start(self, event) -> None:
        if self.said:
            return
        fn = getattr(event.data.get("dispatcher"), "py_func", None)
        if not str(getattr(fn, "__module__", "")).startswith("inerterlab"):
            return  # numba's own helpers compile inside ours
        self.said = True
        stream = self.stream if self.stream is not None else sys.stderr
        try:
            terminal = stream.isatty()
        except (AttributeError, ValueError, OSError):
            terminal = False
        if terminal:
            print(COMPILE_NOTICE, file=stream, flush=True)

    def on_end(self, event) -> None:
        pass


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``inerterlab`` script; returns the exit status.

    Warnings raised by the libraries while a command runs are collected and shown
    once each, after the command's output or its error line.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args
    if debug:
        args.remove("--debug")
    with warnings.catch_warnings(record=True) as caught:
        # numba's note that first-class function types are experimental, at the
        # integrator's first compilation: nothing a user can act on (systems._compiled)
        warnings.filterwarnings("ignore", message=FIRST_CLASS_WARNING)
        notice = CompileNotice()
        _nb_event.register("numba:compile", notice)
        try:
            return _main(args, debug)
        finally:
            _nb_event.unregister("numba:compile", notice)
            seen = set()
            for w in caught:
                line = one_line(f"{w.category.__name__}: {w.message}")
                if line not in seen:
                    seen.add(line)
                    print(f"inerterlab: warning: {line}", file=sys.stderr)


def _main(args: list[str], debug: bool) -> int:
    try:
        rc = app(args=args, prog_name="inerterlab", standalone_mode=False)
        if isinstance(rc, int) and not isinstance(rc, bool):
            if rc == 130:  # typer turns Ctrl-C into this exit code without a word
                print(_INTERRUPTED, file=sys.stderr)
            return rc
    except typer.Exit as e:
        code = getattr(e, "exit_code", None)
        return int(code if code is not None else (e.args[0] if e.args else 0))
    except _cx.NoArgsIsHelpError as e:
        e.show() if hasattr(e, "show") else print(e.format_message())
        return 0
    except typer.Abort:
        print(_INTERRUPTED, file=sys.stderr)
        return 130
    except _cx.UsageError as e:
        cmd = (
            f" {e.ctx.command_path.split(' ', 1)[1]}" if e.ctx and " " in e.ctx.command_path else ""
        )
        _say(f"inerterlab: error: {one_line(_usage_message(e), 300)} (see 'inerterlab{cmd} --help')")
        return 2
    except _cx.ClickException as e:
        _say(f"inerterlab: error: {e.format_message()}")
        return 2
    except Interrupted as e:
        _say(f"inerterlab: {e}")
        return 130
    except InerterlabError as e:
        if debug:
            raise
        _say(f"inerterlab: error: {e}")
        return 2
    except KeyboardInterrupt:
        print(_INTERRUPTED, file=sys.stderr)
        return 130
    except SystemExit as e:
        # click turns a broken pipe into exit 1; it is the reader's choice, not an error
        if isinstance(e.__context__, BrokenPipeError):
            return 0
        raise
    except BrokenPipeError:
        # the reader of our output went away (``| head``): stop quietly, as Unix tools do
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except OSError:
            pass
        return 0
    except OSError as e:  # the system refused: disk full, read-only, permissions, ...
        if debug:
            raise
        _say(f"inerterlab: error: {_os_error_message(e)}")
        return 2
    except RecursionError as e:
        if debug:
            raise
        _say(f"inerterlab: error: input nested too deeply ({e})")
        return 2
    except MemoryError:
        if debug:
            raise
        print(
            "inerterlab: error: out of memory; reduce the size of the run "
            "(horizon, sample rate, grid, number of points)",
            file=sys.stderr,
        )
        return 2
    except Exception as e:  # noqa: BLE001 - last-resort guard for the command line
        if debug:
            raise
        _say(
            f"inerterlab: internal error: {type(e).__name__}: {one_line(e, 300)} "
            "(rerun with --debug for the traceback)"
        )
        return 1
    return 0


def _run() -> None:  # pragma: no cover - console script shim
    sys.exit(main())
