"""``boltwatch serve opcua`` under cProfile, for ``bench_opcua_publish.py --profile FILE``.

    python tests/benchmarks/opcua_profiled_server.py FILE opcua --config ...

The service as shipped, with its functions wrapped on the way in: the work
thread's (the asyncio loop: zenoh's results into the address space and the
events, asyncua's requests, its encoding and encryption) and ResultManagement's
method callbacks (``GetResultById``...), which asyncua runs in its thread pool
(each thread its own profiler, on for the calls only). When the service stops, every
profile is merged into ``FILE`` (``pstats``); the bench prints its heaviest.
"""

from __future__ import annotations

import cProfile
import functools
import pstats
import sys
import threading
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
if str(REPO) not in sys.path:  # run as a script from anywhere
    sys.path.insert(0, str(REPO))

from services.cli.main import main
from services.opcua import service

PROFILES: list[cProfile.Profile] = []
_LOCAL = threading.local()
_LOCK = threading.Lock()


def _profile() -> cProfile.Profile:
    """This thread's profiler."""
    profile: cProfile.Profile | None = getattr(_LOCAL, "profile", None)
    if profile is None:
        profile = _LOCAL.profile = cProfile.Profile()
        with _LOCK:
            PROFILES.append(profile)
    return profile


def profiled(function: Any) -> Any:
    @functools.wraps(function)
    def run(*args: Any, **kwargs: Any) -> Any:
        profile = _profile()
        profile.enable()
        try:
            return function(*args, **kwargs)
        finally:
            profile.disable()

    return run


def install(path: Path) -> None:
    """The wrappers, and ``path`` written when the work thread ends."""
    work = service.OpcuaService.work
    methods = service.result_management_methods

    def profiled_work(self: service.OpcuaService, stop: threading.Event) -> None:
        try:
            profiled(work)(self, stop)
        finally:
            with _LOCK:
                merged = pstats.Stats(PROFILES[0])
                for profile in PROFILES[1:]:
                    merged.add(profile)
            merged.dump_stats(path)

    service.OpcuaService.work = profiled_work  # type: ignore[method-assign]
    service.result_management_methods = lambda *args: {
        name: profiled(callback) for name, callback in methods(*args).items()
    }


if __name__ == "__main__":
    install(Path(sys.argv[1]))
    sys.exit(main(["serve", *sys.argv[2:]]))
