"""Joining a Ray cluster at ``--address`` (``agents.sweep`` and ``agents.search``): the address
is tried with a bounded wait before Ray is asked (Ray itself retries an unreachable address for
minutes), and Ray's refusals come back as one line naming ``--address``, a cluster with token
authentication (docs/clusters.md) included.
"""

from __future__ import annotations

import socket
from urllib.parse import urlsplit

CONNECT_TIMEOUT_S = 5.0
"""How long the command waits for a Ray address to accept a connection."""

TOKEN_HELP = (
    "set RAY_AUTH_MODE=token and give the cluster's token as RAY_AUTH_TOKEN or in the file "
    "RAY_AUTH_TOKEN_PATH names (default ~/.ray/auth_token)"
)
"""How to join a cluster that uses token authentication (docs/clusters.md)."""


def check_reachable(address: str) -> None:
    """``ValueError`` unless ``address`` (``host:port`` or ``ray://host:port``) accepts a TCP
    connection within :data:`CONNECT_TIMEOUT_S`. ``auto`` and ``local`` are Ray's own words and
    pass through."""
    if address in ("auto", "local"):
        return
    parts = urlsplit(address if "://" in address else f"//{address}")
    try:
        host, port = parts.hostname, parts.port
    except ValueError:
        host, port = None, None
    if not host or port is None:
        raise ValueError(f"--address must be HOST:PORT or ray://HOST:PORT, got {address!r}")
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S):
            pass
    except OSError as error:
        raise ValueError(
            f"--address: no Ray cluster answers at {address!r} ({error.strerror or error}); "
            f"start one with 'ray start --head' or leave --address out to run on this machine"
        ) from None


def join(address: str, **options: object) -> None:
    """``ray.init`` at ``address`` (checked by :func:`check_reachable` first) with ``options``;
    ``ValueError`` naming ``--address`` when Ray refuses, saying how to pass a token where the
    cluster asks for one."""
    import ray

    check_reachable(address)
    authentication = getattr(ray.exceptions, "AuthenticationError", ())
    try:
        ray.init(address=address, **options)
    except authentication as error:
        ray.shutdown()
        reason = getattr(error, "message", "") or type(error).__name__
        raise ValueError(
            f"--address: the Ray cluster at {address!r} uses token authentication ({reason}); "
            f"{TOKEN_HELP}"
        ) from None
    except (ConnectionError, RuntimeError) as error:
        ray.shutdown()
        first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        if "token" in str(error).lower() or "authentic" in str(error).lower():
            first += f"; the cluster may use token authentication: {TOKEN_HELP}"
        raise ValueError(
            f"--address: cannot join the Ray cluster at {address!r}: {first}"
        ) from None
