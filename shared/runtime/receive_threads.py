"""Callbacks on zenoh's receive threads, made cheap: each thread keeps its Python thread state.

Zenoh's receive threads are not Python threads: for each callback pyo3 asks
CPython for the GIL with ``PyGILState_Ensure``, which, on a thread with no
Python thread state, makes one and frees it again when the callback returns
(with a ``mmap``/``munmap`` of its frame stack). :func:`keep_thread_state`,
called first in a callback, calls ``PyGILState_Ensure`` once more on a
thread whose state it has not kept yet (a mark in a ``threading.local``,
which lives in that very thread state) and never releases it: that thread
keeps its thread state, later callbacks only take the GIL. A kept state is
freed only when the process ends (zenoh's receive threads live as long as
their runtime). On CPython only; elsewhere it does
nothing (a fresh thread state per callback: slower, still correct).

The inbox variants measured side by side (``bench_line_inbox.py``):
``docs/explanation/design.md``, "Receive threads and inboxes".

:data:`ONE_RECEIVE_THREAD` is the ``ZENOH_RUNTIME`` a service sets (before
its first session opens) so that callbacks never pass the GIL between two of
zenoh's receive threads.
"""

from __future__ import annotations

import ctypes
import os
import platform
import threading

_CPYTHON = platform.python_implementation() == "CPython"
_KEPT = threading.local()  # lives in the thread state: set once it is kept

#: zenoh's receive pool at one thread (read when the first session opens)
ONE_RECEIVE_THREAD = "(rx: (worker_threads: 1))"


def keep_thread_state() -> None:
    """Keep the calling (foreign) thread's Python thread state for the thread's life."""
    if getattr(_KEPT, "kept", False):
        return
    if _CPYTHON:
        ctypes.pythonapi.PyGILState_Ensure()  # holds the GIL already: only counts up
    _KEPT.kept = True


def use_one_receive_thread() -> None:
    """Ask zenoh for one receive thread, unless ``ZENOH_RUNTIME`` already says otherwise."""
    os.environ.setdefault("ZENOH_RUNTIME", ONE_RECEIVE_THREAD)
