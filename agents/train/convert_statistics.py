"""Convert observation statistics pickled by earlier versions into data.

    python -m agents.train.convert_statistics NAME_vecnormalize.pkl [...]

Earlier versions saved a model's ``VecNormalize`` beside it with :mod:`pickle`, and reading a
pickle runs whatever code it names. This converter reads such a file without running any: its
unpickler knows only the classes a ``VecNormalize`` save holds (``VecNormalize``,
``RunningMeanStd``, Gymnasium's spaces, NumPy's arrays and random generators), and builds each
as an inert record of its state instead of the class itself; any other name refuses the file.
From the records it takes the running means, variances and counts and the settings, checks
them (:meth:`etsc_envs.sb3_models.ObservationStatistics.read`'s checks) and writes
``NAME_vecnormalize.npz`` beside the pickle, which it then removes.
"""

from __future__ import annotations

import argparse
import importlib
import io
import pickle
import sys
from pathlib import Path
from typing import Any

import numpy as np

from etsc_envs.core.files import atomic_write_bytes
from etsc_envs.sb3_models import (
    LEGACY_NORMALIZATION_SUFFIX,
    NORMALIZATION_SUFFIX,
    ObservationStatistics,
)


class _Record:
    """An inert stand-in for an allowed class: keeps the arguments and the state it is given."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.args = args

    def __setstate__(self, state: Any) -> None:
        self.state = state


RECORDED = {
    ("stable_baselines3.common.vec_env.vec_normalize", "VecNormalize"),
    ("stable_baselines3.common.running_mean_std", "RunningMeanStd"),
    ("gymnasium.spaces.box", "Box"),
    ("gymnasium.spaces.discrete", "Discrete"),
    ("gymnasium.spaces.multi_binary", "MultiBinary"),
    ("gymnasium.spaces.multi_discrete", "MultiDiscrete"),
    ("numpy.random._pickle", "__generator_ctor"),
    ("numpy.random._pickle", "__bit_generator_ctor"),
    ("numpy.random._pcg64", "PCG64"),
    ("numpy.random.bit_generator", "__pyx_unpickle_SeedSequence"),
    ("numpy.random.bit_generator", "SeedSequence"),
}
"""The names a pickled ``VecNormalize`` refers to that are read as :class:`_Record`."""
NUMPY = {
    ("numpy", "dtype"),
    ("numpy", "ndarray"),
    ("numpy._core.multiarray", "_reconstruct"),
    ("numpy._core.multiarray", "scalar"),
    ("numpy.core.multiarray", "_reconstruct"),
    ("numpy.core.multiarray", "scalar"),
}
"""NumPy's own names for arrays, dtypes and scalars, read as themselves."""


class _StatisticsUnpickler(pickle.Unpickler):
    """Builds only :data:`RECORDED` records and NumPy arrays; any other name is refused."""

    def find_class(self, module: str, name: str) -> Any:
        if (module, name) in RECORDED:
            return _Record
        if (module, name) in NUMPY:
            return getattr(importlib.import_module(module), name)
        raise pickle.UnpicklingError(f"it names {module}.{name}, not part of a VecNormalize")


def _state(record: Any, what: str) -> dict[str, Any]:
    if not isinstance(record, _Record) or not isinstance(getattr(record, "state", None), dict):
        raise ValueError(f"{what} is not a recorded object")
    return record.state


def convert(path: str | Path) -> Path:
    """Write the statistics of the pickled ``VecNormalize`` at ``path`` as ``.npz`` beside it
    (removing the pickle) and return the new file, or ``ValueError`` naming ``path``."""
    path = Path(path)
    if not path.name.endswith(LEGACY_NORMALIZATION_SUFFIX):
        raise ValueError(f"{path}: expected a file named NAME{LEGACY_NORMALIZATION_SUFFIX}")
    try:
        top = _StatisticsUnpickler(io.BytesIO(path.read_bytes())).load()
        state = _state(top, "the file")
        observations, returns = (_state(state[key], key) for key in ("obs_rms", "ret_rms"))
        statistics = ObservationStatistics(
            observation_mean=np.asarray(observations["mean"]),
            observation_var=np.asarray(observations["var"]),
            observation_count=observations["count"],
            return_mean=returns["mean"],
            return_var=returns["var"],
            return_count=returns["count"],
            clip_obs=state["clip_obs"],
            clip_reward=state["clip_reward"],
            gamma=state["gamma"],
            epsilon=state["epsilon"],
            norm_obs=state["norm_obs"],
            norm_reward=state["norm_reward"],
        )
        data = statistics.to_bytes()
    except Exception as error:  # whatever a foreign or damaged pickle makes the reader raise
        raise ValueError(
            f"{path} is not a pickled VecNormalize ({type(error).__name__}: {error})"
        ) from None
    target = path.with_name(path.name.removesuffix(LEGACY_NORMALIZATION_SUFFIX))
    target = target.with_name(target.name + NORMALIZATION_SUFFIX)
    staged = atomic_write_bytes(target.with_name(f".{target.name}.checking"), data)
    try:
        ObservationStatistics.read(staged)  # the same checks as every load
        staged.replace(target)
    finally:
        staged.unlink(missing_ok=True)
    path.unlink()
    return target


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m agents.train.convert_statistics",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("files", nargs="+", metavar=f"NAME{LEGACY_NORMALIZATION_SUFFIX}")
    args = parser.parse_args(argv)
    failed = 0
    for path in args.files:
        try:
            print(f"wrote {convert(path)}")
        except (OSError, ValueError) as error:
            print(f"error: {error}", file=sys.stderr)
            failed += 1
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
