"""A memo for the expensive shared computations of the report chapters.

Like :func:`functools.lru_cache` (unbounded), but an entry can also be computed in
another process and put in (:meth:`Memo.put`), which is how a parallel reproduction
shares one brute-force curve or one identification between the items that use it.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Hashable
from typing import Any


class Memo:
    """Memoised ``fn``; the key is the call's arguments with defaults filled in."""

    def __init__(self, fn: Callable[..., Any]):
        self.fn = fn
        self.signature = inspect.signature(fn)
        self.cache: dict[Hashable, Any] = {}
        functools.update_wrapper(self, fn)

    def key(self, *args, **kwargs) -> tuple:
        bound = self.signature.bind(*args, **kwargs)
        bound.apply_defaults()
        return tuple(bound.arguments.values())

    def __call__(self, *args, **kwargs):
        k = self.key(*args, **kwargs)
        try:
            return self.cache[k]
        except KeyError:
            value = self.cache[k] = self.fn(*k)
            return value

    def put(self, key: tuple, value: Any) -> None:
        """Store ``value`` as the result for the full argument tuple ``key``."""
        self.cache[tuple(key)] = value

    def cache_clear(self) -> None:
        self.cache.clear()


def memo(fn: Callable[..., Any]) -> Memo:
    """Decorator form of :class:`Memo`."""
    return Memo(fn)
