"""``python -m agents.sweep --config configs/sweeps/NAME.yaml``: see :mod:`agents.sweep.runner`."""

from agents.sweep.runner import main

if __name__ == "__main__":
    raise SystemExit(main())
