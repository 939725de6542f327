"""Where units of work run: this process, a pool of ``--jobs`` local processes, or a
``dask.distributed`` cluster (``--dask ADDRESS``, or ``--dask local`` for a ``LocalCluster``).

Every place that fans work out (a run's cases and catalogue entries) submits the same units
through :func:`executor` and collects them in submission order, so the results do not depend
on where they ran. Dask is the optional extra ``dask``; it is imported only when asked for.
"""

from __future__ import annotations

from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import contextmanager

from dyncheck.errors import InvalidInput

LOCAL = "local"
"""``--dask local``: a ``LocalCluster`` of ``--jobs`` single-threaded worker processes."""

CONNECT_SECONDS = 20
"""How long to wait for a scheduler before giving up (an error, before any work)."""


@contextmanager
def executor(jobs: int = 1, dask: str | None = None) -> Iterator[Executor | None]:
    """A ``concurrent.futures`` executor for the units of work, or None to run them here.

    ``dask``: a scheduler address (``tcp://host:8786``) or :data:`LOCAL`; a scheduler that
    cannot be reached, or dask not installed, is an :class:`InvalidInput` naming ``--dask``.
    """
    if dask is None:
        if jobs <= 1:
            yield None
            return
        import multiprocessing

        ctx = multiprocessing.get_context("spawn")  # JAX and Warp do not survive a fork
        with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx) as pool:
            yield pool
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InvalidInput(
            "--dask", dask, "used with the extra 'dask' installed (pip install 'dyncheck[dask]')"
        ) from None
    if dask == LOCAL:
        cluster = LocalCluster(
            n_workers=max(jobs, 1),
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
        )
        with cluster, Client(cluster) as client:
            yield client.get_executor(pure=False)
        return
    try:
        client = Client(dask, timeout=CONNECT_SECONDS)
    except (OSError, TimeoutError, ValueError) as exc:
        why = type(exc).__name__
        raise InvalidInput(
            "--dask", dask, f"a reachable dask scheduler (tcp://HOST:PORT) or 'local' ({why})"
        ) from None
    with client:
        yield client.get_executor(pure=False)
