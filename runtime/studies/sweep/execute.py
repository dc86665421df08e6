"""Run a sweep: serially in this process, or on Dask (a LocalCluster on all cores, or a running cluster).

The scenes of all points are built and checked here first (a bad value stops the sweep before any work, naming
the point, the key, the value and the allowed range). Points whose part-file exists are skipped (resume). The
others run through :func:`.point.run_point`, at most a few per worker in flight, and each row is written by this
process as soon as it arrives. Dask reschedules the points of a worker that dies, so a killed worker costs only
the points it was running. Ctrl-C (or SIGTERM) stops the running points at their next check, serially and on
Dask alike, keeps every finished point and drops those cut short; the same command resumes.
"""

from __future__ import annotations

import logging
import signal
import threading
import time
import uuid
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from ....cores import MAX_WORKERS, available_cores
from .design import checked_points
from .point import run_point
from .store import Store
from .study import Study, StudyError
from .watch import EVERY_S, Bar, running_on, watching_here


@dataclass(eq=False)
class SweepReport:
    """What a sweep did: the table of every finished point, and counts of this run. ``==`` is identity (compare two
    sweeps' tables with ``a.table.equals(b.table)``)."""

    table: pd.DataFrame
    folder: Path
    total: int  # points of the study
    skipped: int  # already done (resumed)
    computed: int  # finished in this run
    failed: int  # of all finished points: status other than completed
    wall_time_s: float
    interrupted: bool
    workers: int
    where: str  # "serial", "LocalCluster", or the scheduler address
    workers_asked: int | None = None  # the workers asked, when more than the points left to run (then n is those)
    retried: int = 0  # of those computed now, points whose earlier rows had not completed (retry_failed)
    #: the study was edited since ``folder`` was written: (rows kept, as the edited study's points, and counted in
    #: ``skipped``; rows discarded: their points are not the edited study's, or their scene or quantities changed)
    carried: tuple[int, int] | None = None

    @property
    def complete(self) -> bool:
        return len(self.table) == self.total

    def describe(self) -> str:
        rate = self.computed / self.wall_time_s if self.wall_time_s > 0 else 0.0
        head = "interrupted" if self.interrupted else "done"
        again = f" ({self.retried} of them again: their rows had not completed)" if self.retried else ""
        edited = ""
        if self.carried is not None:
            kept, dropped = self.carried
            edited = (f" ({kept} of them kept from the study before its edit, the same scene and quantities; "
                      f"{dropped} of its rows discarded)")
        return (f"{head}: {len(self.table)} of {self.total} points in {self.folder}/ ({self.computed} computed now"
                f"{again}, {self.skipped} resumed{edited}, {self.failed} not completed); {self.wall_time_s:.1f} s, "
                f"{rate:.2f} points/s "
                f"on {self.workers} worker{'s' if self.workers != 1 else ''} ({self.where}"
                + (f"; {self.workers_asked} asked, as many as points left" if self.workers_asked else "") + ")")


def scenes_of(study: Study) -> list[tuple[int, Any, dict[str, Any]]]:
    """(point, scene, overrides) of every point, each scene checked (by :func:`.study.load_study` already, for a
    study it read: its ``points_checked``); bad points raise :class:`StudyError`, each distinct problem once with the points
    it refuses (:func:`.design.checked_points`)."""
    if study.points_checked is not None and study.points_checked[0] == study.content_hash():
        return list(study.points_checked[1])
    points, problems, note = checked_points(study)
    if problems:
        raise StudyError(problems, source=study.source, note=note)
    return points


def point_scene(study: Study | str | Path, point: int):
    """The scene of point ``point`` of ``study`` (a :class:`Study` or a study file's path), as the sweep runs it: to
    simulate that point alone with every output a run keeps (``apexseal.simulate(point_scene(study, 3))``; the sweep
    keeps a row of numbers per point). A point outside the study is a ValueError naming the allowed range."""
    if isinstance(study, str | Path):
        from .study import load_study

        study = load_study(study)
    points = scenes_of(study)
    if isinstance(point, bool) or not isinstance(point, int) or not 0 <= point < len(points):
        raise ValueError(f"point = {point!r}: allowed: an integer 0 <= point <= {len(points) - 1} (the study "
                         f"{study.name} has {len(points)} points, numbered as its table's point column)")
    return points[point][1]


def run_sweep(study: Study | str | Path, out: str | Path, *, workers: int | None = None, scheduler: str | None = None,
              client=None, resume: bool = True, retry_failed: bool = False, quiet: bool = False,
              on_row: Callable[[dict], None] | None = None,
              on_start: Callable[[], None] | None = None) -> SweepReport:
    """Run every point of ``study`` (a :class:`Study`, or a study file's path: :func:`.study.load_study`) not yet in
    ``out`` and return the table of all finished points.

    ``workers``: processes of the default LocalCluster (default: every core; 1 runs serially in this process).
    ``scheduler``: address of a running Dask scheduler (``tcp://host:8786``) to use instead. ``client``: a
    ``dask.distributed.Client`` to use as it is. ``resume=False`` discards earlier results in ``out``;
    ``retry_failed=True`` computes again the points of ``out`` whose rows did not complete (a point that failed on
    a crashed worker, a wall-time budget or an error since fixed), each row kept until its new one replaces it.
    ``on_row``: called with each finished point's row. ``on_start``: called once every point is checked and
    ``out`` is taken for the study, before anything runs (never for a study refused: :class:`StudyError`, or a
    folder of another study: :class:`~.store.StoreError`).

    A Ctrl-C stops the running points (every finished one is kept in ``out``); then, in a script,
    :class:`~apexseal.signals.RunInterrupted` carries the report (``interrupted`` True), in an interactive session
    the report is returned with a warning, and a SIGTERM ends the process once the points are kept.
    """
    from ....signals import StopSignals
    from ...api import after_an_interrupt

    if isinstance(study, str | Path):  # a study file, as simulate takes a scene file
        from .study import load_study

        study = load_study(study)
    elif not isinstance(study, Study):
        raise TypeError(f"study = {study!r:.80}: expected a Study (apexseal.load_study(path)) or a study file's path")
    check_workers(workers)
    if retry_failed and not resume:
        raise ValueError("retry_failed = True with resume = False: resume = False discards every point in out, so "
                         "none is there to compute again; allowed: one of them")
    t0 = time.perf_counter()
    points = scenes_of(study)
    # the scheduler is reached before the folder is taken: one that does not answer leaves nothing written
    with StopSignals.abandoning():  # a signal while it waits for the scheduler (up to 30 s) stops at once
        own_client = connect(scheduler) if client is None and scheduler is not None else None
    store = Store(out)
    stop = StopSignals(redeliver_term=True)  # the points' own signal handling shares it (nested)
    try:
        with stop as signals:
            report = _sweep(store, study, points, t0, workers, scheduler, own_client or client, resume,
                            retry_failed, quiet, on_row, on_start)
            left = report.total - len(report.table)
            return after_an_interrupt(report, stop, signals, report.interrupted, "the sweep",
                                      f"{len(report.table)} of {report.total} points finished, kept in {report.folder} "
                                      f"(run_sweep again with the same folder computes the {left} left)")
    finally:
        store.close()
        if own_client is not None:
            own_client.close()


class SchedulerError(OSError):
    """No Dask scheduler answered at the address given (``scheduler`` of :func:`run_sweep`, ``--scheduler``)."""

    def __init__(self, address: str, reason: str) -> None:
        self.address, self.reason = address, reason
        super().__init__(self.describe("scheduler = ", repr(address)))

    def describe(self, field: str = "--scheduler ", value: str | None = None) -> str:
        return (f"{field}{value or self.address}: no Dask scheduler answered there ({self.reason}); allowed: the "
                "address of a running Dask scheduler, as `dask scheduler` prints it (e.g. tcp://10.0.0.5:8786)")


def connect(address: str):
    """A ``dask.distributed.Client`` of the scheduler at ``address``, or :class:`SchedulerError`: nothing there
    (Dask tries for ``distributed.comm.timeouts.connect``, 30 s by default) or a server that is not Dask's (its
    first bytes were read as a message's length, a MemoryError)."""
    from dask.distributed import Client

    try:
        _probe(address)
        return Client(address)
    except Exception as err:  # noqa: BLE001 - whatever answered, it was no scheduler
        raise SchedulerError(address, f"{type(err).__name__}: {err}") from err


def _probe(address: str) -> None:
    """Dask's handshake with ``address`` in a thread of its own that ends with it: a Client that finds no scheduler
    leaves its event loop's thread ("IO loop") running for the life of the process, and a process with threads
    cannot fork its figure worker safely (runtime/results/figure_worker.py). Raises what the handshake raised."""
    import asyncio

    from distributed.comm import connect as handshake

    async def reach() -> None:
        comm = await handshake(address)
        await comm.close()

    failed: list[BaseException] = []

    def run() -> None:
        try:
            asyncio.run(reach())
        except BaseException as err:  # noqa: BLE001 - handed to the caller's thread
            failed.append(err)

    probe = threading.Thread(target=run, name="apexseal-scheduler-probe", daemon=True)
    probe.start()
    probe.join()
    if failed:
        raise failed[0]


def check_workers(workers: Any) -> None:
    """A ValueError naming the value and the allowed range unless ``workers`` is None or an integer from 1 to
    :data:`MAX_WORKERS` (a LocalCluster of no workers, or of a negative number, waited for ever for its first point;
    0 was taken as every core)."""
    import numbers

    if workers is None or (isinstance(workers, numbers.Integral) and not isinstance(workers, bool)
                           and 1 <= workers <= MAX_WORKERS):
        return
    raise ValueError(f"workers = {workers!r}: allowed: an integer 1 <= n <= {MAX_WORKERS} (1: serially in this "
                     "process), or None (a worker per core)")


def _sweep(store, study, points, t0, workers, scheduler, client, resume, retry_failed, quiet, on_row,
           on_start) -> SweepReport:
    from tqdm.auto import tqdm

    from ....progress import bar_output

    done = store.open(study, resume=resume, points=points)
    retried = store.not_completed() & done if retry_failed else set()
    done -= retried
    if on_start is not None:
        on_start()
    todo = [p for p in points if p[0] not in done]
    skipped = len(points) - len(todo)
    n = workers or available_cores()
    asked = None  # the workers asked, where the sweep's own LocalCluster starts fewer (the points left)
    if client is None and scheduler is None and todo:
        capped = local_workers(n, len(todo))
        asked, n = (n if capped < n else None), capped
    serial = (client is None and scheduler is None and n == 1) or not todo  # nothing to do: no cluster
    bar = tqdm(total=len(points), initial=skipped, unit="pt", disable=quiet, desc=study.name, dynamic_ncols=True,
               **bar_output())  # in a log a line at a time
    shown = Bar(bar)  # finished and failed points, and how far the long ones running have got (watch.py)

    recorded: set[int] = set()

    def record(row: dict) -> None:
        store.write(row)
        recorded.add(int(row["point"]))
        shown.point_done(row["status"])
        if on_row is not None:
            on_row(row)

    args = (study.quantities, study.max_wall_time)
    try:
        if todo and client is None and scheduler is None and not _models_built(todo, quiet):
            where, interrupted = "nothing computed: stopped while the models were built", True
        elif serial:
            with watching_here(shown):
                where, interrupted = "serial" if todo else "nothing left to compute", _serial(todo, args, record)
        else:
            where, n, interrupted = _dask(todo, args, record, study, n, scheduler, client, shown)
    finally:
        bar.close()
    table = store.consolidate(study)
    return SweepReport(table=table, folder=store.folder, total=len(points), skipped=skipped,
                       computed=len(recorded), failed=int((table["status"] != "completed").sum()),
                       wall_time_s=time.perf_counter() - t0, interrupted=interrupted, workers=n, where=where,
                       workers_asked=asked, retried=len(recorded & retried), carried=store.carried)


def _models_built(todo, quiet: bool) -> bool:
    """Derive, generate and compile here, once, the model of each distinct set of effects and assumptions the
    points need (usually one), with the stages' progress on stderr unless ``quiet``: the points find them in the
    cache (a cold model takes seconds to minutes; inside the points it was built silently, by every worker at
    once). False when a signal stopped it (nothing is computed yet). A model that fails to build is left to its
    points, which record the failure as their rows (the sweep goes on with the others)."""
    from ....progress import enabled
    from ....signals import StopSignals
    from ...api import model_functions

    models = {}
    for _, scene, _ in todo:
        key = (scene.effects, scene.assumptions, scene.solver.compile, scene.solver.interpreted)
        models.setdefault(key, scene)
    try:
        with StopSignals() as signals, enabled(not quiet):
            for scene in models.values():
                try:
                    model_functions(scene)
                except Exception:  # noqa: BLE001 - each of its points records why (run_point)
                    pass
                if signals.requested:
                    return False
    except KeyboardInterrupt:  # StopSignals.abandoning stops a build at once
        return False
    return True


def _serial(todo, args, record) -> bool:
    """Points one after the other in this process.

    SIGINT (Ctrl-C) and SIGTERM are caught for the whole loop by the run's own :class:`StopSignals` (each
    ``simulate`` joins it): the running point stops at its next integrator call and is dropped (a point cut short
    by a signal is not a result; the resumed sweep computes it), every finished point is kept.
    """
    from ....signals import StopSignals

    try:
        with StopSignals() as signals:
            for i, scene, overrides in todo:
                if signals.requested:
                    return True
                row = run_point(i, scene, overrides, *args)
                if signals.requested and row["status"] != "completed":
                    return True
                record(row)
            return signals.requested
    except KeyboardInterrupt:  # outside the main thread signals are not caught
        return True


class WorkersWarning(UserWarning):
    """A sweep's LocalCluster started with fewer workers than asked (no more than points left to run), or with
    more workers than this process has cores."""


def local_workers(asked: int, left: int) -> int:
    """The workers of a sweep's own LocalCluster: ``asked``, but never more than the ``left`` points to run (each
    worker runs one point at a time; those beyond had nothing to do, and starting a thousand processes took
    minutes on two cores), with a :class:`WorkersWarning` for a cap, and one for more workers than cores: a point
    is single-threaded, so workers beyond the cores share them, finish no sooner in all, and cost memory and
    start-up time (not refused: the count of cores a process is given may be smaller than what runs it)."""
    n = min(asked, left)
    if n < asked:
        how = "it runs in this process, as with 1 worker" if n == 1 else f"the LocalCluster starts {n} workers"
        warnings.warn(f"workers = {asked}: {left} point{'s' if left != 1 else ''} left to run, so {how} (a worker "
                      "runs one point at a time)", WorkersWarning, stacklevel=3)
    cores = available_cores()
    if n > cores:
        warnings.warn(f"{n} worker processes on {cores} core{'s' if cores != 1 else ''}: each point is single-"
                      "threaded, so workers beyond the cores share them, finish no sooner in all and cost memory "
                      f"and start-up time; allowed, but --workers {cores} is as fast", WorkersWarning, stacklevel=3)
    return n


def local_cluster(workers: int):
    """A LocalCluster of ``workers`` processes with one thread each (the model is single-threaded C).

    Its processes start with SIGINT blocked for their life: a Ctrl-C on the terminal reaches the whole process
    group, and this process, which stops the sweep and then the cluster, is the one to act on it (each worker
    printed a KeyboardInterrupt traceback). This process holds SIGINT while the cluster is made
    (:func:`~apexseal.signals.held`: the cluster's threads, and the processes they start, inherit the block), so
    a Ctrl-C in those seconds reaches its handler once the cluster is up, instead of being lost, as it was while
    this process ignored SIGINT for the workers to inherit that; :func:`local_workers` keeps their number to
    the points left. Python's resource tracker, started here before the block when it is not running yet, would
    otherwise be started by the cluster's thread as it starts the first worker, and unblock SIGINT in that thread
    for good as it does so (``multiprocessing.resource_tracker.ensure_running``): the workers got the Ctrl-C, and
    their start failed with their KeyboardInterrupt tracebacks."""
    from dask.distributed import LocalCluster

    from ....signals import held

    _tracker_running()
    with held(signal.SIGINT):
        return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                            silence_logs=logging.CRITICAL)  # shutdown races of dask print ERRORs


def _tracker_running() -> None:
    """Start Python's multiprocessing resource tracker now, in this thread, if it is not running (POSIX only)."""
    try:
        from multiprocessing import resource_tracker
    except ImportError:  # no such tracker where processes are not forked or spawned the POSIX way
        return
    ensure = getattr(resource_tracker, "ensure_running", None)
    if ensure is not None and hasattr(signal, "pthread_sigmask"):
        ensure()


def _started_cluster(workers: int):
    """:func:`local_cluster`, its failure to start explained where the usual cause is the main script: each worker
    process imports it, so a script that calls run_sweep at its top level starts another sweep in every worker (it
    needs the ``__main__`` guard), and a script with no file to import (read from standard input, ``python - <
    sweep.py``: its ``__file__`` is ``"<stdin>"``) cannot be imported at all, guard or not. A main module without a
    ``__file__`` (``python -c``, an interactive session) is not imported by the workers."""
    import __main__

    try:
        return local_cluster(workers)
    except RuntimeError as err:
        script = getattr(__main__, "__file__", None)
        if script is None or "failed to start" not in str(err):
            raise
        if not Path(script).is_file():
            raise RuntimeError(f"Dask could not start the sweep's worker processes ({err}). Each worker imports the "
                               f"main script, and this one has no file ({script}"
                               f"{': it was read from standard input' if script == '<stdin>' else ''}), so "
                               "an `if __name__ == \"__main__\":` guard cannot help: save the script to a file and "
                               "run that, or run the points in this process with workers=1") from err
        raise RuntimeError(f"Dask could not start the sweep's worker processes ({err}). Each worker imports the "
                           f"script {Path(script).name}; a script that calls run_sweep at its top level starts "
                           "another sweep in every worker: call it under `if __name__ == \"__main__\":`") from err


#: how often (s) the wait for a cluster's points looks whether a signal came
POLL_S = 0.05


def _dask(todo, args, record, study, n, scheduler, client, shown):
    """The points on a Dask cluster (the one at ``scheduler``, ``client``'s, or a LocalCluster of ``n`` workers).

    SIGINT and SIGTERM are caught as the serial path catches them (:class:`StopSignals`, for the whole sweep),
    whenever they come in the cluster's life: while the cluster starts, a signal is noted and acted on once the
    start has finished (seconds; nothing is computed yet): the cluster is closed and no point submitted (abandoning
    the start halfway left a cluster that could not be closed: an ``AssertionError: Status.init`` traceback at
    exit); while the points run, it is acted on within :data:`POLL_S`, never in the middle of writing a row: the
    points not started are cancelled, those running are stopped at their next check (:func:`_stop`), every
    finished one is kept; and the cluster this sweep started is closed, a signal while it closes only noted."""
    from ....signals import StopSignals

    try:
        with StopSignals() as signals:
            return _on_cluster(todo, args, record, study, n, scheduler, client, signals, shown)
    except KeyboardInterrupt:  # outside the main thread signals are not caught
        return scheduler or "LocalCluster", n, True


def _on_cluster(todo, args, record, study, n, scheduler, client, signals, shown):
    from dask.distributed import Client, as_completed

    own_cluster = own_client = None
    try:
        if client is None:  # (a scheduler's client is made by run_sweep, before the folder is taken)
            own_cluster = _started_cluster(n)  # a signal meanwhile is noted: the start is never cut halfway
            client = own_client = Client(own_cluster)
        where = scheduler or ("LocalCluster" if own_cluster is not None else str(client.scheduler.address))
        n = max(1, len(client.scheduler_info(n_workers=-1).get("workers", {})) or n)
        if signals.requested:  # while the cluster started: nothing is computed yet, none is submitted
            return where, n, True
        # this run of the sweep: its points' task keys, and what stops them on the workers (point.stop_points)
        stop_key = f"apexseal-sweep-{study.content_hash()[:12]}-{uuid.uuid4().hex[:8]}"
        queue = iter(todo)
        running: set = set()

        def submit(point):
            i, scene, overrides = point
            fut = client.submit(run_point, i, scene, overrides, *args, stop_key=stop_key, key=f"{stop_key}-{i}",
                                pure=False)
            running.add(fut)
            return fut

        flight = as_completed([submit(p) for p in _take(queue, 2 * n)])
        looked = time.monotonic()  # when the bar last showed the long points
        while not flight.is_empty():
            if signals.requested:
                _stop(client, running, stop_key, signals.received[0])
                flight.clear()
                return where, n, True
            done = flight.next_batch(block=False)
            if not done and not shown.bar.disable and time.monotonic() - looked > EVERY_S:
                shown.show_running(running_on(client, stop_key))
                looked = time.monotonic()
            elif not done:
                time.sleep(POLL_S)
            for fut in done:
                record(fut.result())
                running.discard(fut)
                fut.release()
                for p in _take(queue, 1):
                    flight.add(submit(p))
        return where, n, signals.requested
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()


def _stop(client, futures, stop_key: str, signum: int) -> None:
    """Stop a sweep's points on the cluster: cancel those not done (no other one starts), and stop those running
    on every worker as a signal stops a serial sweep's point (:func:`.point.stop_points`): at the run's next
    check, not when the point would have ended. Their rows are never written (a point cut short is not a result;
    the resumed sweep computes it)."""
    from .point import stop_points

    client.cancel(list(futures))
    client.run(stop_points, stop_key, signum, on_error="ignore")


def _take(it, k: int) -> list:
    out = []
    for _ in range(k):
        try:
            out.append(next(it))
        except StopIteration:
            break
    return out
