"""The progress of a long job on standard error, with an estimate of the time left.

A :class:`JobProgress` counts a job's work in sampling instants (its episodes' steps, planned
ahead) and says what the job is doing now. On a terminal it is a tqdm bar; when standard error
is redirected (a log file, a pipe, CI) it writes a plain line at each new stage and at most
every :data:`LINE_EVERY_S` seconds in between, each with the share done, the time elapsed and
the time left at the job's mean rate so far::

    [ 12%] paper 000: run 2/4 (P2) | 0:41 elapsed, about 5:02 left

While a job is open (``with JobProgress(...)``), the episode runners' progress bars
(:func:`etsc_envs.evaluation.episodes.instants_bar`) report their instants to it instead of drawing
bars of their own, so code deep inside a job reports its progress without being handed the job.
"""

from __future__ import annotations

import sys
import time
from typing import IO, Any

from tqdm import tqdm

LINE_EVERY_S = 20.0
"""Seconds between two progress lines of a redirected job (a new stage writes one at once)."""

_open_jobs: list[JobProgress] = []


def current_job() -> JobProgress | None:
    """The innermost open :class:`JobProgress`, or ``None``."""
    return _open_jobs[-1] if _open_jobs else None


def clock(seconds: float) -> str:
    """``seconds`` as ``M:SS`` (or ``H:MM:SS`` from an hour on)."""
    minutes, secs = divmod(round(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{secs:02d}" if hours else f"{minutes}:{secs:02d}"


class JobProgress:
    """Progress of a job of ``total`` sampling instants, as a context manager.

    Args:
        total: the job's planned work, in sampling instants (> 0).
        stream: where to write (standard error by default); a bar if it is a terminal,
            plain lines otherwise.
        line_every_s: seconds between two lines when ``stream`` is not a terminal.
    """

    def __init__(
        self, total: int, stream: IO[str] | None = None, line_every_s: float = LINE_EVERY_S
    ) -> None:
        if total <= 0:
            raise ValueError(f"total must be a number of sampling instants > 0, got {total!r}")
        self.total = int(total)
        self.stream = sys.stderr if stream is None else stream
        self.line_every_s = line_every_s
        self.done = 0
        self.stage_text = ""
        self._started = time.perf_counter()
        self._last_line = -float("inf")
        isatty = getattr(self.stream, "isatty", None)
        self._bar = (
            tqdm(total=self.total, file=self.stream, unit="step", unit_scale=True, smoothing=0)
            if isatty is not None and isatty()
            else None
        )

    def __enter__(self) -> JobProgress:
        _open_jobs.append(self)
        return self

    def __exit__(self, *exc: Any) -> None:
        _open_jobs.remove(self)
        if self._bar is not None:
            self._bar.close()

    @property
    def elapsed_s(self) -> float:
        return time.perf_counter() - self._started

    def left_s(self) -> float | None:
        """The time left at the job's mean rate so far (``None`` before any work is done)."""
        if self.done <= 0:
            return None
        return self.elapsed_s * (self.total - self.done) / self.done

    def stage(self, text: str) -> None:
        """Say what the job does now (a line at once when redirected)."""
        self.stage_text = text
        if self._bar is not None:
            self._bar.set_description(text)
        else:
            self._line()

    def advance(self, instants: int) -> None:
        """Count ``instants`` more sampling instants done (never beyond the total)."""
        step = max(0, min(int(instants), self.total - self.done))
        self.done += step
        if self._bar is not None:
            self._bar.update(step)
        elif time.perf_counter() - self._last_line >= self.line_every_s:
            self._line()

    def reach(self, instants: int) -> None:
        """Count the work done up to ``instants`` of the total (for a stage that ended before
        its planned instants, an episode that failed early)."""
        self.advance(instants - self.done)

    def write(self, text: str, stream: IO[str] | None = None) -> None:
        """Write ``text`` and a newline to ``stream`` (standard output by default) without
        breaking the bar."""
        target = sys.stdout if stream is None else stream
        if self._bar is not None:
            self._bar.write(text, file=target)
        else:
            print(text, file=target, flush=True)

    def _line(self) -> None:
        left = self.left_s()
        estimate = "estimating the time left" if left is None else f"about {clock(left)} left"
        share = 100.0 * self.done / self.total
        print(
            f"[{share:3.0f}%] {self.stage_text} | {clock(self.elapsed_s)} elapsed, {estimate}",
            file=self.stream,
            flush=True,
        )
        self._last_line = time.perf_counter()


class JobBar:
    """An episode's progress bar inside an open job: its ``update`` counts instants for the
    job (the interface of tqdm that :func:`etsc_envs.evaluation.episodes.instants_bar` callers
    use)."""

    def __init__(self, job: JobProgress) -> None:
        self.job = job

    def update(self, instants: int = 1) -> None:
        self.job.advance(instants)

    def close(self) -> None:
        pass

    def __enter__(self) -> JobBar:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
