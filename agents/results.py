"""``python -m agents.results ENV_ID --model PATH``: the command of :mod:`agents.judge.results`."""

from agents.judge.results import main

if __name__ == "__main__":
    raise SystemExit(main())
