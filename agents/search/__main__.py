"""``python -m agents.search --config configs/search/NAME.yaml``: :mod:`agents.search.cma_es`."""

from agents.search.cma_es import main

if __name__ == "__main__":
    raise SystemExit(main())
