"""A signal whose KeyboardInterrupt Python drops: the case the package's interrupt count exists for."""

from __future__ import annotations

import os
import signal
import weakref


def interrupt_in_a_weakref_callback(signum: int = signal.SIGTERM) -> None:
    """Send ``signum`` to this process from inside a weakref callback, where its handler then runs: Python prints
    "Exception ignored" and drops the KeyboardInterrupt (as in matplotlib's callbacks while plots are drawn)."""

    class Node:
        pass

    node = Node()

    def callback(_ref: object) -> None:
        os.kill(os.getpid(), signum)
        for _ in range(10_000):  # the handler runs between bytecodes, here
            pass

    ref = weakref.ref(node, callback)
    del node
    assert ref() is None
