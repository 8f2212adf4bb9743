"""File output: atomic for regular files, streamed for devices, FIFOs and ``-``.

A regular file is written beside the target and renamed over it: a reader never sees
a half-written file, and a failure leaves the previous file (if any) untouched and no
temporary file behind. The new file gets the mode a plain ``open`` would give it (the
umask applied to 0666) or keeps the mode of the file it replaces.

What is not a regular file is never replaced:

* ``-`` writes to standard output;
* a character device (``/dev/null``, a terminal), a FIFO or a socket-like special file
  that already exists, and any existing path under ``/dev`` or ``/proc`` (such as
  ``/dev/stdout``, even when it is redirected to a file), is opened and written in place;
* a symbolic link is followed: the file it points to is written (atomically if it is a
  regular file) and the link itself stays;
* a directory is refused with a :class:`~inerterlab.errors.ParameterError`, and so is a
  new file in a folder that does not exist (a mistyped folder is not made).
"""

from __future__ import annotations

import os
import shutil
import stat
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = [
    "read_text_limited",
    "read_bytes_limited",
    "read_toml",
    "loads_toml",
    "replace_directory",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "current_umask",
    "output_target",
]


def current_umask() -> int:
    """The process umask, read without changing it where the system allows."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # pragma: no cover - systems without /proc
    os.umask(mask)  # pragma: no cover
    return mask  # pragma: no cover


def output_target(
    path: str | os.PathLike, option: str = "output", follow_links: bool = True
) -> tuple[str, Path | None]:
    """Classify an output path: ``("stdout", None)``, ``("stream", p)`` or ``("file", p)``.

    ``p`` is the path to write with links followed (``follow_links=False``, for the
    package's own working files, replaces a link instead). Raises ``ParameterError``
    naming ``option`` for an empty path, a directory, or a new file whose folder does not
    exist (a mistyped folder is refused, never made; the package's own working files,
    ``follow_links=False``, get their folder made by :func:`atomic_path`).
    """
    from .errors import ParameterError

    text = os.fspath(path)
    if not follow_links:
        return "file", Path(os.path.abspath(text))
    if text == "-" or _descriptor(str(text)) == 1:
        return "stdout", None
    if not str(text).strip():
        raise ParameterError(option, text, "a file path (it is empty)")
    try:
        st = os.stat(text)  # follows links, also the /proc "magic" ones behind /dev/stdout
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise ParameterError(option, text, f"a usable file path ({e.strerror})") from None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise ParameterError(option, text, "a file path; it is a directory")
    if st is None:
        folder = Path(os.path.abspath(text)).parent
        if not folder.is_dir():  # a mistyped folder is refused, not made
            what = "is not a folder" if folder.exists() else "does not exist"
            raise ParameterError(option, text, f"a file in an existing folder ({folder} {what})")
    real = os.path.realpath(text)
    if st is not None and (
        not stat.S_ISREG(st.st_mode) or _is_system_path(str(text)) or _is_system_path(real)
    ):
        # a device, FIFO or socket, or a descriptor such as /dev/stdout (even when it is
        # redirected to a file): written in place, never replaced
        return "stream", Path(text)
    return "file", Path(real)


def _is_system_path(path: str) -> bool:
    return path.startswith(("/dev/", "/proc/"))


def _descriptor(path: str) -> int | None:
    """The descriptor number a path such as /dev/stdout or /dev/fd/3 names, else None."""
    import re

    named = {"/dev/stdin": 0, "/dev/stdout": 1, "/dev/stderr": 2}
    if path in named:
        return named[path]
    m = re.fullmatch(rf"/(?:dev/fd|proc/self/fd|proc/{os.getpid()}/fd)/(\d+)", path)
    return int(m.group(1)) if m else None


@contextmanager
def atomic_path(
    path: str | os.PathLike,
    suffix: str = ".tmp",
    option: str = "output",
    follow_links: bool = True,
) -> Iterator[str]:
    """Yield a temporary path; on success its content goes to ``path``.

    For a regular (or new) file the temporary file sits beside the target and is
    renamed onto it; for ``-`` and special files it is copied into them and removed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_path(d / "a.txt") as tmp:
    ...     _ = pathlib.Path(tmp).write_text("done")
    >>> (d / "a.txt").read_text(), sorted(p.name for p in d.iterdir())
    ('done', ['a.txt'])
    """
    kind, p = output_target(path, option, follow_links)
    if kind == "file":
        if not follow_links:  # the package's own working file: its folder is made
            p.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=p.parent, prefix=f".{p.name}.", suffix=suffix)
    else:
        fd, tmp = tempfile.mkstemp(prefix=".inerterlab-out.", suffix=suffix)
    os.close(fd)
    try:
        yield tmp
        if kind == "file":
            try:
                mode = stat.S_IMODE(os.stat(p).st_mode)
            except FileNotFoundError:
                mode = 0o666 & ~current_umask()
            os.chmod(tmp, mode)
            os.replace(tmp, p)
        else:
            with open(tmp, "rb") as src:
                if kind == "stdout":
                    sys.stdout.flush()
                    shutil.copyfileobj(src, sys.stdout.buffer)
                    sys.stdout.buffer.flush()
                elif _descriptor(str(p)) is not None:
                    # write through the descriptor itself: reopening /dev/fd/N would
                    # truncate a file it is redirected to and lose its offset
                    fd = _descriptor(str(p))
                    if fd == 2:
                        sys.stderr.flush()
                    while chunk := src.read(1 << 16):
                        view = memoryview(chunk)
                        while view:
                            view = view[os.write(fd, view) :]
                else:
                    with open(p, "wb") as dst:
                        shutil.copyfileobj(src, dst)
            os.unlink(tmp)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_bytes(
    path: str | os.PathLike, data: bytes, option: str = "output", follow_links: bool = True
) -> Path:
    """Write ``data`` to ``path`` (atomically for a regular file)."""
    with atomic_path(path, option=option, follow_links=follow_links) as tmp:
        Path(tmp).write_bytes(data)
    return Path(path)


def atomic_write_text(path: str | os.PathLike, text: str, option: str = "output") -> Path:
    """Write ``text`` to ``path`` (atomically for a regular file)."""
    with atomic_path(path, option=option) as tmp:
        Path(tmp).write_text(text)
    return Path(path)


def clean_stale_siblings(target: Path) -> list[Path]:
    """Remove ``.<name>.new-*`` / ``.<name>.old-*`` folders an interrupted
    :func:`replace_directory` left beside ``target``."""
    import re

    target = Path(target)
    pat = re.compile(re.escape(f".{target.name}.") + r"(new-[A-Za-z0-9_]+|old-\d+)")
    removed = []
    if target.parent.is_dir():
        for p in target.parent.iterdir():
            if pat.fullmatch(p.name) and p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)
                removed.append(p)
    return removed


def replace_directory(target: str | os.PathLike, files: dict[str, bytes | str]) -> Path:
    """Write ``files`` ({relative path: content}) as a new directory that replaces ``target``.

    The new directory is filled beside ``target`` and swapped in with two renames, so a
    crash or a full disk leaves either the old directory or the new one, never a mix.
    The caller decides beforehand that whatever is at ``target`` may be replaced.
    Leftovers of an interrupted earlier call are removed first.
    """
    target = Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    clean_stale_siblings(target)
    tmp = Path(tempfile.mkdtemp(dir=target.parent, prefix=f".{target.name}.new-"))
    try:
        os.chmod(tmp, 0o777 & ~current_umask())
        for rel, data in files.items():
            p = tmp / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            with open(p, "wb") as fh:
                fh.write(data.encode() if isinstance(data, str) else data)
                fh.flush()
                os.fsync(fh.fileno())
        old = None
        if target.exists():
            old = target.parent / f".{target.name}.old-{os.getpid()}"
            os.replace(target, old)
        os.replace(tmp, target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return target


def input_size_limit() -> int:
    """Largest input file read into memory [bytes]: 1/16 of the memory budget, at most 1 GiB.

    Parsing text into numbers takes several times the file's size.
    """
    from .resources import MEMORY_FRACTION, available_memory

    return int(min(1024**3, MEMORY_FRACTION * available_memory() / 16))


#: the most a reader waits for a FIFO, a pipe or a device to deliver its data [s]
#: (environment variable ``INERTERLAB_READ_TIMEOUT`` overrides it)
READ_TIMEOUT = 10.0
#: the size cap of a text configuration file (vehicle, car, sweep, manifest) [bytes]
CONFIG_SIZE_LIMIT = 16 * 1024**2
#: the most read from a FIFO, a pipe or a device, whose size is not known beforehand
STREAM_SIZE_LIMIT = 64 * 1024**2


def _read_timeout() -> float:
    try:
        t = float(os.environ.get("INERTERLAB_READ_TIMEOUT", READ_TIMEOUT))
    except ValueError:
        t = READ_TIMEOUT
    return t if t > 0 and t == t else READ_TIMEOUT


def read_bytes_limited(
    path: str | os.PathLike, what: str, limit: int | None = None, timeout: float | None = None
) -> bytes:
    """The bytes of an input file, at most ``limit`` of them, or ``DataFileError``.

    A regular file is checked by its size before it is read. Anything else (a FIFO, a
    pipe, a device such as ``/dev/zero``) is opened without blocking and read up to the
    limit (at most :data:`STREAM_SIZE_LIMIT`), waiting at most ``timeout`` seconds in all (:data:`READ_TIMEOUT`): a FIFO
    nobody writes into, or a device that never ends, is refused instead of blocking
    or filling the memory. Every error names the file.
    """
    import select
    import time

    from .errors import DataFileError

    p = Path(path)
    limit = input_size_limit() if limit is None else int(limit)
    timeout = _read_timeout() if timeout is None else float(timeout)
    try:
        st = os.stat(p)
    except OSError as e:
        raise DataFileError(p, f"cannot read the {what} ({e.strerror or e})") from None
    if stat.S_ISDIR(st.st_mode):
        raise DataFileError(p, f"is a directory, not a {what}")
    if stat.S_ISREG(st.st_mode):
        if st.st_size > limit:
            raise DataFileError(
                p, f"is {st.st_size} bytes; a {what} may have at most {limit} bytes here"
            )
        try:
            with open(p, "rb") as fh:
                data = fh.read(limit + 1)
        except OSError as e:
            raise DataFileError(p, f"cannot read the {what} ({e.strerror or e})") from None
        if len(data) > limit:  # it grew while being read
            raise DataFileError(p, f"holds more than {limit} bytes; too large for a {what}")
        return data
    limit = min(limit, STREAM_SIZE_LIMIT)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as e:
        raise DataFileError(p, f"cannot read the {what} ({e.strerror or e})") from None
    buf = bytearray()
    deadline = time.monotonic() + timeout
    fifo = stat.S_ISFIFO(st.st_mode)
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                got = f"delivered {len(buf)} bytes and no end of file" if buf else "no data"
                raise DataFileError(
                    p,
                    f"{got} within {timeout:g} s (a FIFO or device nobody writes to?); "
                    f"save the {what} to a regular file",
                )
            ready, _, _ = select.select([fd], [], [], min(left, 0.05))
            if not ready:
                continue
            try:
                chunk = os.read(fd, min(1 << 20, limit + 1 - len(buf)))
            except BlockingIOError:
                continue
            if not chunk:
                if fifo and not buf:
                    # no writer yet (reported as end of file): wait for one until the
                    # deadline rather than take the FIFO for an empty file
                    time.sleep(min(0.05, max(0.0, left)))
                    continue
                break
            buf += chunk
            if len(buf) > limit:
                raise DataFileError(p, f"holds more than {limit} bytes; too large for a {what}")
    except OSError as e:
        raise DataFileError(p, f"cannot read the {what} ({e.strerror or e})") from None
    finally:
        os.close(fd)
    return bytes(buf)


def read_text_limited(
    path: str | os.PathLike, what: str, limit: int | None = None, timeout: float | None = None
) -> str:
    """The UTF-8 text of an input file, read by :func:`read_bytes_limited`.

    A file that is not UTF-8 text, or holds NUL bytes (a binary file), is refused
    naming the byte.
    """
    from .errors import DataFileError

    p = Path(path)
    data = read_bytes_limited(p, what, limit, timeout)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise DataFileError(
            p, f"not a UTF-8 text file (byte {e.start}); a {what} is text"
        ) from None
    nul = text.find("\0")
    if nul >= 0:
        raise DataFileError(
            p,
            f"holds a NUL byte (byte {nul}): a binary file, not a {what}",
            text.count("\n", 0, nul) + 1,
        )
    return text


def loads_toml(text: str, source: str, what: str = "file") -> dict:
    """Parse TOML text, every failure a ``DataFileError`` naming ``source`` (and the line)."""
    import re
    import tomllib

    from .errors import DataFileError

    if not isinstance(text, str):
        raise DataFileError(source, f"expected TOML text, got {type(text).__name__}")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        m = re.search(r"line (\d+)", str(e))
        raise DataFileError(
            source, f"not valid TOML: {e}", int(m.group(1)) if m else None
        ) from None
    except RecursionError:
        raise DataFileError(
            source, f"not usable TOML: values nested too deeply for a {what}"
        ) from None


def read_toml(
    path: str | os.PathLike, what: str, limit: int = CONFIG_SIZE_LIMIT
) -> tuple[str, dict]:
    """``(text, data)`` of a TOML file, read size-capped by :func:`read_text_limited`."""
    text = read_text_limited(path, what, limit=limit)
    return text, loads_toml(text, str(path), what)
