"""The sweep's progress bar between points: how far its long points have got.

The bar counts finished points; a point that runs for minutes (many revolutions, a slow method) left it still for
that long. Each run reports its revolutions (``apexseal.progress.following_runs``) to the point that runs it
(:func:`.point.running_points`), and the bar shows those running for more than :data:`LONG_POINT_S`, e.g.
``failed=0, point 12: 3.5/20 rev, 1m05s``: serially read by a thread of this process every :data:`EVERY_S`, on
Dask gathered from the workers (``Client.run``) as often.
"""

from __future__ import annotations

import contextlib
import threading

#: a point running for longer than this (s) is shown in the bar with its revolutions
LONG_POINT_S = 2.0
#: how often (s) the bar shows the long points
EVERY_S = 1.0
#: long points named in the bar (the longest running); the others are counted
SHOWN = 2


def _duration(s: float) -> str:
    m, s = divmod(int(s), 60)
    return f"{m}m{s:02d}s" if m else f"{s}s"


def describe(running: dict[int, tuple[float, int, float]]) -> str:
    """The long points of ``running`` (point -> (revolutions done, asked, seconds running)), longest first:
    ``point 12: 3.5/20 rev, 1m05s; point 3: 0.2/20 rev, 4s; 2 more``; "" when none runs that long."""
    long = sorted(((t, i, d, n) for i, (d, n, t) in running.items() if t >= LONG_POINT_S), reverse=True)
    # a point whose run has not begun (its model building or compiling) has no revolutions yet: "0/0 rev" was said
    shown = [f"point {i}: {f'{d:.3g}/{n} rev' if n else 'starting'}, {_duration(t)}" for t, i, d, n in long[:SHOWN]]
    if len(long) > SHOWN:
        shown.append(f"{len(long) - SHOWN} more")
    return "; ".join(shown)


class Bar:
    """The sweep's tqdm bar: finished points, the failed ones, the invalid ones (refused at their start for their
    scene's values: no failure of the run, counted apart as the closing lines count them) and the long points
    running."""

    def __init__(self, bar) -> None:
        self.bar, self.failed, self.invalid, self.running = bar, 0, 0, ""

    def point_done(self, status: str) -> None:
        """A point finished with ``status`` (a row's, point.STATUSES)."""
        self.invalid += status == "invalid"
        self.failed += status not in ("completed", "invalid")
        self.running = ""  # perhaps the point just done: the next look says which still run
        self._show(refresh=False)
        self.bar.update(1)

    def show_running(self, running: dict) -> None:
        text = describe(running)
        if text or text != self.running:  # a long point's time moves on
            self.running = text
            self._show(refresh=True)

    def _show(self, refresh: bool) -> None:
        post = (f"failed={self.failed}" + (f", invalid={self.invalid}" if self.invalid else "")
                + (f", {self.running}" if self.running else ""))
        self.bar.set_postfix_str(post, refresh=refresh)


@contextlib.contextmanager
def watching_here(bar: Bar):
    """Inside the block a thread shows the long points of this process (a serial sweep) every :data:`EVERY_S`."""
    from .point import running_points

    if bar.bar.disable:
        yield
        return
    stop = threading.Event()

    def loop() -> None:
        while not stop.wait(EVERY_S):
            bar.show_running(running_points())

    thread = threading.Thread(target=loop, name="apexseal-sweep-progress", daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()


def running_on(client, stop_key: str) -> dict[int, tuple[float, int, float]]:
    """The points of the sweep ``stop_key`` running on the workers of ``client``'s cluster."""
    from .point import running_points

    out: dict = {}
    for found in client.run(running_points, stop_key, on_error="return").values():
        if isinstance(found, dict):
            out.update(found)
    return out
