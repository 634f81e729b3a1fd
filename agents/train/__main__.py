"""``python -m agents.train --config configs/train/NAME.yaml``: see :mod:`agents.train.training`."""

from agents.train.training import main

if __name__ == "__main__":
    raise SystemExit(main())
