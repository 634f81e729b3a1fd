"""``python -m agents.leaderboard``: the command of :mod:`agents.judge.leaderboard`."""

from agents.judge.leaderboard import main

if __name__ == "__main__":
    raise SystemExit(main())
