"""A local Dask cluster set up for sweeps: `local_dask_client`, and `DASK_SWEEP_CONFIG`, the
Dask settings it applies (set the same keys on your own cluster)."""
from __future__ import annotations

import os
import sys

__all__ = ["DASK_SWEEP_CONFIG", "local_dask_client"]


#: Dask settings for a cluster that runs long CPU-bound sweep tasks on a few cores, where every
#: cycle Dask spends on itself is taken from a run (docs/performance.md measures them). Each
#: turns off or slows a service such sweeps do not use: the statistical profiler (a sample of
#: every worker thread each 10 ms), work stealing (a rebalance each 100 ms; a sweep's tasks are
#: equal chunks handed out as workers free up), and the system and memory monitors (each
#: 500 and 100 ms; a point holds a few MB). Last, the worker processes' malloc: the nanny sets
#: MALLOC_TRIM_THRESHOLD_=64 KiB, which also turns off glibc's adaptive mmap threshold, so every
#: block over 128 KiB a run allocates (its outputs, CVODE's memory) is mapped anew and faulted in,
#: page by page: 0.6-0.8 ms a point, a sixth of its cost. A point's memory is a few MB, so
#: keeping up to 64 MiB of free heap per worker costs nothing.
DASK_SWEEP_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.scheduler.work-stealing": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": 64 << 20,
    "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_": 32 << 20,
}


def local_dask_client(n_workers: int = 2, processes: bool = True, **kwargs):
    """A ``distributed.Client`` on a new LocalCluster of `n_workers` single-threaded workers,
    set up for sweeps (DASK_SWEEP_CONFIG; its HTTP server on a free port, so that two clusters do
    not warn about port 8787); closing the client closes the cluster:

        if __name__ == "__main__":          # in a script: each worker process imports it
            with pyspline.local_dask_client(2) as client:
                ds = pyspline.sweep(case, executor=client.get_executor(), l_x=values)

    processes : True (default, as Dask's LocalCluster): one process per worker, with a nanny
        each, the layout of a multi-node cluster. The worker processes start by importing the
        script that starts them, so in a script the cluster must start under
        ``if __name__ == "__main__":``; without the guard this raises a RuntimeError that says
        so, as it does for a script read from standard input (no file to import). False: the
        workers are threads of this process (the core releases the GIL): they start in 0.03 s
        instead of 1-2 s and need no guard, but Dask's event loop then shares the GIL and the
        cores with them: on sweeps of cheap points (5 ms each, 2 cores) they scaled less than
        worker processes in five of six runs: medians of 1.47-1.66x against 1.57-1.92x
        (docs/performance.md, "What Dask costs").
    kwargs : passed to LocalCluster (e.g. dashboard_address=':8787' to watch the sweep: the
        dashboard needs bokeh)."""
    import multiprocessing

    import dask
    from distributed import Client
    if processes:
        if getattr(multiprocessing.current_process(), "_inheriting", False):
            # a new process still importing the script of its parent (multiprocessing's test)
            raise RuntimeError(
                "pyspline.local_dask_client was called while a Dask worker process imported the "
                "script that starts the cluster: in a script, start the cluster under `if "
                "__name__ == \"__main__\":`, or pass processes=False for worker threads")
        script = getattr(sys.modules.get("__main__"), "__file__", None)
        if script is not None and not os.path.isfile(script):
            raise RuntimeError(
                f"pyspline.local_dask_client: worker processes start by importing the script "
                f"that starts them, and {script} is not a file (a script read from standard "
                f"input?): save the script to a file, or pass processes=False for worker "
                f"threads in this process")
    options = dict(n_workers=n_workers, threads_per_worker=1, processes=processes,
                   dashboard_address=":0")
    options.update(kwargs)
    with dask.config.set(DASK_SWEEP_CONFIG):
        try:
            return Client(**options)
        except Exception as exc:
            if not processes:
                raise
            raise RuntimeError(
                f"pyspline.local_dask_client: the Dask worker processes did not start "
                f"({str(exc).rstrip('.')}). "
                "If a script starts the cluster, it must do so under `if __name__ == "
                "\"__main__\":`, because each worker process imports the script (Dask's log "
                "above shows each worker's error); or pass processes=False for worker threads "
                "in this process") from exc
