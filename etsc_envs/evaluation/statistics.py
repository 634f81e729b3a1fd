"""Statistics of the test protocol: aggregates with 95 % intervals and paired comparisons.

Every interval here is a 95 % interval from the field's libraries, never hand-rolled:

* one policy on a scenario set — mean, median and interquartile mean (IQM, the 25 % trimmed
  mean) of a per-scenario metric, with a percentile bootstrap interval of the mean and of the
  IQM (:func:`scipy.stats.bootstrap`, scenarios resampled);
* a failure (or settling) rate — the exact Clopper–Pearson interval (:meth:`scipy.stats.binomtest`);
* two triggers on the same scenarios — the per-scenario ratios ``a_i / b_i`` (paired by seed):
  their IQM with a bootstrap interval, the ratio of the means with a paired bootstrap interval,
  and the probability of improvement ``P(a_i < b_i)`` (ties count one half) with its interval;
* several training seeds of one method — the IQM over seeds × scenarios of the per-scenario
  ratios with rliable's stratified bootstrap interval, resampling the scenarios and the
  training runs within each (``task_bootstrap``: a scenario set is a sample of its
  distribution, so the interval must cover other draws of it, not only other seeds; over
  runs alone, seeds that learned one policy give an interval of zero width), and the range of
  the per-seed IQMs.

Every bootstrap uses :data:`BOOTSTRAP_RESAMPLES` resamples from a generator seeded with
:data:`BOOTSTRAP_SEED`, so a JSON file is reproduced digit for digit.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy import stats

CONFIDENCE = 0.95
"""The confidence level of every interval."""

BOOTSTRAP_RESAMPLES = 10_000
"""Resamples of every bootstrap interval."""

BOOTSTRAP_SEED = 0
"""Seed of the bootstrap resampling (intervals are reproducible)."""

IQM_TRIM = 0.25
"""The interquartile mean drops this fraction of the values at each end."""


def iqm(values: np.ndarray, axis: int = -1) -> np.ndarray:
    """The interquartile mean: the mean of the middle half (``scipy.stats.trim_mean``)."""
    return stats.trim_mean(values, IQM_TRIM, axis=axis)


def _bootstrap_interval(
    data: tuple[np.ndarray, ...], statistic: Callable[..., np.ndarray], paired: bool = False
) -> list[float]:
    """The percentile bootstrap interval of ``statistic`` over ``data`` (a constant sample, or
    a single value, gives the degenerate interval at the statistic itself)."""
    point = float(statistic(*data, axis=-1))
    if len(data[0]) < 2 or all(np.ptp(sample) == 0.0 for sample in data):
        return [point, point]
    result = stats.bootstrap(
        data,
        statistic,
        paired=paired,
        vectorized=True,
        confidence_level=CONFIDENCE,
        n_resamples=BOOTSTRAP_RESAMPLES,
        method="percentile",
        rng=np.random.default_rng(BOOTSTRAP_SEED),
    )
    return [float(result.confidence_interval.low), float(result.confidence_interval.high)]


def summarize(values: Sequence[float]) -> dict[str, Any]:
    """``n``, mean, median and IQM of ``values`` with bootstrap intervals of the mean
    (``mean_ci95``) and of the IQM (``iqm_ci95``)."""
    sample = np.asarray(values, dtype=float)
    if sample.size == 0 or not np.all(np.isfinite(sample)):
        raise ValueError(f"values must be a non-empty sequence of finite numbers, got {values!r}")
    return {
        "n": int(sample.size),
        "mean": float(sample.mean()),
        "mean_ci95": _bootstrap_interval((sample,), np.mean),
        "median": float(np.median(sample)),
        "iqm": float(iqm(sample)),
        "iqm_ci95": _bootstrap_interval((sample,), iqm),
    }


def proportion_summary(flags: Sequence[bool]) -> dict[str, Any]:
    """Count and rate of the true ``flags`` (failed, settled, ...) with the exact
    (Clopper–Pearson) 95 % interval of the rate."""
    marked = np.asarray(flags, dtype=bool)
    if marked.size == 0:
        raise ValueError("flags must name at least one episode")
    count = int(marked.sum())
    interval = stats.binomtest(count, int(marked.size)).proportion_ci(
        confidence_level=CONFIDENCE, method="exact"
    )
    return {
        "n": int(marked.size),
        "count": count,
        "rate": count / marked.size,
        "rate_ci95": [float(interval.low), float(interval.high)],
    }


def _ratio_of_means(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    return np.mean(a, axis=axis) / np.mean(b, axis=axis)


def _improvement(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    return np.mean((a < b) + 0.5 * (a == b), axis=axis)


def paired_ratio(
    candidate: Sequence[float] | np.ndarray, reference: Sequence[float] | np.ndarray
) -> dict[str, Any]:
    """``candidate`` against ``reference`` on the same scenarios (lower is better).

    Returns the per-scenario ratios' IQM and median (``iqm``, ``iqm_ci95``, ``median``), the
    ratio of the means with its paired interval (``ratio_of_means``,
    ``ratio_of_means_ci95``), and the probability of improvement ``P(candidate < reference)``
    per scenario (``probability_of_improvement`` and its interval). Where the reference is 0
    the ratio is 1 if the candidate is 0 too; a scenario where only the reference is 0 has no
    ratio and is counted in ``worse_where_reference_zero`` (the candidate is worse there,
    whatever the ratios say). ``iqm`` is ``None`` when no scenario has a ratio.
    """
    a = np.asarray(candidate, dtype=float)
    b = np.asarray(reference, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or a.size == 0:
        raise ValueError(
            f"candidate and reference must be equal-length 1-D samples, got {a.shape}, {b.shape}"
        )
    result: dict[str, Any] = {
        "n": int(a.size),
        "probability_of_improvement": float(_improvement(a, b)),
        "probability_of_improvement_ci95": _bootstrap_interval((a, b), _improvement, True),
    }
    both_zero = (b == 0.0) & (a == 0.0)
    defined = (b != 0.0) | both_zero
    result["worse_where_reference_zero"] = int(np.sum((b == 0.0) & (a != 0.0)))
    if defined.any():
        ratios = np.where(both_zero, 1.0, a / np.where(b == 0.0, 1.0, b))[defined]
        result.update(
            iqm=float(iqm(ratios)),
            iqm_ci95=_bootstrap_interval((ratios,), iqm),
            median=float(np.median(ratios)),
        )
    else:
        result.update(iqm=None, iqm_ci95=None, median=None)
    if np.all(b != 0.0):
        result["ratio_of_means"] = float(_ratio_of_means(a, b))
        result["ratio_of_means_ci95"] = _bootstrap_interval((a, b), _ratio_of_means, True)
    else:  # a resample of the zero references alone has no ratio of means
        result["ratio_of_means"] = result["ratio_of_means_ci95"] = None
    return result


def _stratified_bootstrap(
    scores: np.ndarray, statistic: Callable[[np.ndarray], np.ndarray], task_bootstrap: bool
) -> tuple[float, list[float]]:
    """rliable's stratified bootstrap of ``statistic`` over ``(runs, scenarios)`` scores: the
    point estimate and its percentile interval.

    rliable draws its resamples from NumPy's global generator (``np.random.choice``), not from
    the ``random_state`` it hands to arch, so the global generator is seeded with
    :data:`BOOTSTRAP_SEED` for the call and restored after it: the interval is then the same in
    every process.
    """
    from rliable import library as rly

    state = np.random.get_state()
    np.random.seed(BOOTSTRAP_SEED)
    try:
        with warnings.catch_warnings():
            # arch 7 deprecates the random_state keyword rliable passes (rliable keeps arch
            # below 8, where it is gone)
            warnings.filterwarnings("ignore", "random_state is deprecated", FutureWarning)
            point, interval = rly.get_interval_estimates(
                {"scores": scores},
                statistic,
                task_bootstrap=task_bootstrap,
                reps=BOOTSTRAP_RESAMPLES,
                confidence_interval_size=CONFIDENCE,
                random_state=np.random.RandomState(BOOTSTRAP_SEED),
            )
    finally:
        np.random.set_state(state)
    bounds = interval["scores"]
    return float(point["scores"][0]), [float(bounds[0, 0]), float(bounds[1, 0])]


def seeds_ratio(candidate: np.ndarray, reference: np.ndarray) -> dict[str, Any]:
    """Several training runs of a method against a reference trigger on the same scenarios.

    Args:
        candidate: ``(runs, scenarios)`` values of the learned triggers (one row per seed).
        reference: ``(scenarios,)`` or ``(runs, scenarios)`` values of the reference.

    Returns the IQM over runs × scenarios of the per-scenario ratios with rliable's
    stratified bootstrap interval over scenarios and runs (``iqm``, ``iqm_ci95``), each run's
    own IQM (``per_run``) and their range. Zero references follow :func:`paired_ratio`: 0 / 0
    is 1, and a scenario where a run is above a zero reference leaves the ratios and is counted
    in ``worse_where_reference_zero``; where that leaves no scenario (e.g. a method that fails
    the one paper scenario its reference keeps at cost 0), ``iqm``, ``iqm_ci95``, each run's
    IQM and ``range`` are ``None``.
    """
    from rliable import metrics

    a = np.atleast_2d(np.asarray(candidate, dtype=float))
    b = np.broadcast_to(np.asarray(reference, dtype=float), a.shape)
    worse = np.any((b == 0.0) & (a != 0.0), axis=0)
    if worse.all():
        return {
            "runs": int(a.shape[0]),
            "n": int(a.shape[1]),
            "iqm": None,
            "iqm_ci95": None,
            "per_run": [None] * int(a.shape[0]),
            "range": None,
            "worse_where_reference_zero": int(worse.sum()),
        }
    kept_a, kept_b = a[:, ~worse], b[:, ~worse]
    ratios = np.where(kept_b == 0.0, 1.0, kept_a / np.where(kept_b == 0.0, 1.0, kept_b))
    point, interval = _stratified_bootstrap(
        ratios, lambda scores: np.array([metrics.aggregate_iqm(scores)]), task_bootstrap=True
    )
    per_run = [float(value) for value in iqm(ratios, axis=1)]
    return {
        "runs": int(a.shape[0]),
        "n": int(a.shape[1]),
        "iqm": point,
        "iqm_ci95": interval,
        "per_run": per_run,
        "range": [min(per_run), max(per_run)],
        "worse_where_reference_zero": int(worse.sum()),
    }


def seeds_summary(values: np.ndarray) -> dict[str, Any]:
    """The mean of several training runs' per-scenario values, over runs × scenarios.

    Args:
        values: ``(runs, scenarios)`` values of one method (one row per training seed).

    Returns ``runs``, ``n`` (scenarios), ``mean`` and ``mean_ci95``: with one run the
    percentile bootstrap interval over scenarios (:func:`summarize`); with several, rliable's
    stratified bootstrap interval resampling the scenarios and the runs within each
    (``task_bootstrap``, as :func:`seeds_ratio`), so one scenario's interval spans the seeds.
    A single value has the degenerate interval at itself.
    """
    sample = np.atleast_2d(np.asarray(values, dtype=float))
    if sample.size == 0 or sample.ndim != 2 or not np.all(np.isfinite(sample)):
        raise ValueError(
            f"values must be a (runs, scenarios) array of finite numbers, got {values!r}"
        )
    runs, scenarios = sample.shape
    if runs == 1:
        interval = _bootstrap_interval((sample[0],), np.mean)
    elif np.ptp(sample) == 0.0:
        interval = [float(sample[0, 0])] * 2
    else:
        _, interval = _stratified_bootstrap(
            sample, lambda scores: np.array([np.mean(scores)]), task_bootstrap=scenarios > 1
        )
    return {"runs": runs, "n": scenarios, "mean": float(sample.mean()), "mean_ci95": interval}


AGGREGATED_KEYS = ("mean_cost", "transmissions", "transmission_rate", "return")
"""Per-episode numbers that :func:`aggregate_records` summarises."""


def aggregate_records(records: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """The protocol's aggregates of one policy's episode records: :func:`summarize` of each of
    :data:`AGGREGATED_KEYS`, and :func:`proportion_summary` of the failed episodes
    (``failure``) and of those that settled by the env's own criterion (``settled``, where the
    records carry it)."""
    aggregates: dict[str, Any] = {
        key: summarize([record[key] for record in records]) for key in AGGREGATED_KEYS
    }
    aggregates["failure"] = proportion_summary(
        [record["failure"] is not None for record in records]
    )
    if all("settled" in record for record in records):
        aggregates["settled"] = proportion_summary([record["settled"] for record in records])
    return aggregates


def _interval(values: list[float] | None) -> str:
    return "—" if values is None else f"[{values[0]:.4g}, {values[1]:.4g}]"


def aggregate_lines(aggregates: dict[str, Any]) -> list[str]:
    """:func:`aggregate_records`' output as lines of at most 100 characters."""
    lines = []
    for key, value in aggregates.items():
        if "mean" in value:
            lines.append(
                f"{key:>17s}  mean {value['mean']:.4g} {_interval(value['mean_ci95'])}  "
                f"IQM {value['iqm']:.4g} {_interval(value['iqm_ci95'])}"
            )
        else:
            low, high = value["rate_ci95"]
            lines.append(
                f"{key:>17s}  {value['count']} of {value['n']} ({100 * value['rate']:.3g} %) "
                f"[{100 * low:.3g} %, {100 * high:.3g} %]"
            )
    return lines
