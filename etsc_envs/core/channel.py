"""The held channel: a zero-order hold between a transmitting side and a receiving side.

A channel carries one or several independently triggered values (a vector per channel). The
receiving side only ever sees the value last transmitted on each channel; this class keeps
those held values and the bookkeeping of when they were sent.
"""

from __future__ import annotations

import numpy as np


class HeldChannel:
    """Zero-order hold of ``n_channels`` values with transmission bookkeeping.

    Args:
        n_channels: number of separately triggered channels (one transmit bit each).
        width: length of the value vector each channel carries.
    """

    def __init__(self, n_channels: int, width: int) -> None:
        self.n_channels = n_channels
        self.width = width
        self.held = np.zeros((n_channels, width))
        self.last_sent_s = np.zeros(n_channels)
        self.transmissions = np.zeros(n_channels, dtype=np.int64)
        self.interevent_s: list[list[float]] = [[] for _ in range(n_channels)]

    def reset(self, values: np.ndarray, time_s: float) -> None:
        """Synchronise both sides on ``values`` at ``time_s`` (not counted as a transmission)."""
        self.held[:] = np.reshape(values, (self.n_channels, self.width))
        self.last_sent_s[:] = time_s
        self.transmissions[:] = 0
        self.interevent_s = [[] for _ in range(self.n_channels)]

    def send(self, mask: np.ndarray, values: np.ndarray, time_s: float) -> int:
        """Refresh the held value of every channel whose ``mask`` entry is set; return how many."""
        if not mask.any():
            return 0
        values = np.reshape(values, (self.n_channels, self.width))
        sent = 0
        for channel in np.flatnonzero(mask):
            self.held[channel] = values[channel]
            if self.transmissions[channel] > 0:
                self.interevent_s[channel].append(time_s - self.last_sent_s[channel])
            self.last_sent_s[channel] = time_s
            self.transmissions[channel] += 1
            sent += 1
        return sent

    def time_since_sent(self, time_s: float) -> np.ndarray:
        """Seconds since each channel last carried a value (since reset if it never did)."""
        return time_s - self.last_sent_s
