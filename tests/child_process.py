"""What the tests that interrupt a child process with SIGINT give that child."""

import signal


def interruptible() -> None:
    """A ``preexec_fn``: SIGINT at its default action and unblocked in the child. A test run
    started in the background passes SIGINT on ignored, and a thread of the test process that
    blocked it (its signal mask survives fork and exec) would leave it pending for ever: either
    way the child would never see the test's interrupt."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
