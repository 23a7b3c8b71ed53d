"""Studies on a Dask distributed cluster (`martello study --scheduler ADDRESS`,
docs/studies.md#on-a-dask-cluster): the sweep's runs go to the cluster's workers through a
concurrent.futures executor instead of local processes; everything else (the specs, the
scoring, the rows) is the same, so a cluster study equals the local one row for row.

Each worker needs martello installed (the same version: the rows record it) and the scene
files the study names (ground-motion records are read on the worker). A worker runs one
martello run at a time, whatever its thread count: the native library is not documented to
be thread-safe, and concurrent runs would disturb each other's wall times. Give the
workers one thread each and as many processes as cores (`dask worker ADDRESS --nthreads 1
--nworkers N`)."""

from __future__ import annotations

import threading
from concurrent.futures import Executor
from contextlib import contextmanager

from ..errors import MartelloError

# The scheduler must answer within this many seconds, and have a worker within as many.
CONNECT_TIMEOUT_S = 30

_ONE_RUN_AT_A_TIME = threading.Lock()


def _serialised(fn, *args):
    """fn(*args) on a worker, one at a time per worker process."""
    with _ONE_RUN_AT_A_TIME:
        return fn(*args)


class DaskExecutor(Executor):
    """A concurrent.futures executor over a distributed Client: submit() sends fn(*args)
    to a worker (never deduplicated: two identical specs are two runs)."""

    def __init__(self, client):
        self.client = client
        self._inner = client.get_executor(pure=False)

    def submit(self, fn, /, *args, **kwargs):
        return self._inner.submit(_serialised, fn, *args, **kwargs)

    def shutdown(self, wait=True, *, cancel_futures=False):
        self._inner.shutdown(wait=wait)


@contextmanager
def dask_executor(address, origin="given by --scheduler", timeout=CONNECT_TIMEOUT_S):
    """(executor, number of workers) on the Dask scheduler at address (tcp://host:port, or a
    scheduler file's path); the client is closed on exit. `origin` says where the address
    came from (every message names it). MartelloError with one line naming the fix when Dask
    is missing or nothing answers."""
    where = f"the Dask scheduler {address} ({origin})"
    try:
        from distributed import Client
    except ImportError:
        raise MartelloError(f"{where}: running on a Dask cluster needs Dask's distributed "
                            "scheduler: pip install 'martello[dask]'") from None
    kwargs = {"scheduler_file": address} if str(address).endswith(".json") else {"address": address}
    try:
        client = Client(timeout=timeout, **kwargs)
    except (OSError, TimeoutError, ValueError) as exc:
        raise MartelloError(f"{where}: no Dask scheduler answers there "
                            f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}); "
                            f"start one with `dask scheduler` and workers with `dask worker "
                            f"{address} --nthreads 1`") from None
    try:
        try:
            client.wait_for_workers(1, timeout=timeout)
        except TimeoutError:
            raise MartelloError(f"{where}: the scheduler has no worker after {timeout} s; "
                                f"start some with `dask worker {address} --nthreads 1`") from None
        workers = len(client.nthreads())
        yield DaskExecutor(client), workers
    finally:
        client.close()
