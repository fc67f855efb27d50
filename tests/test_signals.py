"""Signals: children started in ``sigint_blocked_for_children`` cannot be interrupted while they import; SIGTERM as Ctrl-C."""

from __future__ import annotations

import multiprocessing as mp
import os
import signal

import pytest
from helpers.interrupts import interrupt_in_a_weakref_callback

from tpee_ompl.signals import child_sigint, interrupts, sigint_blocked_for_children, sigterm_as_keyboard_interrupt


def _report_sigint(conn) -> None:
    blocked_at_start = signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())
    os.kill(os.getpid(), signal.SIGINT)  # a Ctrl-C while "importing": held, not raised
    child_sigint(signal.SIG_IGN)  # then ignored: the pending one is dropped
    conn.send((blocked_at_start, signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())))
    conn.close()


def test_a_child_starts_with_sigint_blocked_and_a_ctrl_c_before_it_is_ready_does_not_reach_it() -> None:
    ctx = mp.get_context("spawn")
    recv, send = ctx.Pipe(duplex=False)
    with sigint_blocked_for_children():
        proc = ctx.Process(target=_report_sigint, args=(send,))
        proc.start()
    send.close()
    blocked_at_start, blocked_after = recv.recv()
    proc.join(timeout=60)
    assert proc.exitcode == 0 and blocked_at_start and not blocked_after
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, set())  # the parent's mask is back


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_or_sighup_within_the_block_interrupts_like_ctrl_c_and_the_handler_is_restored_after(sig) -> None:
    """SIGHUP (a closed terminal) killed a campaign or a library build at once, its workers left blocked."""
    before = signal.getsignal(sig)
    try:
        with sigterm_as_keyboard_interrupt():
            os.kill(os.getpid(), sig)
            for _ in range(1000):  # the handler runs between bytecodes
                pass
        raise AssertionError(f"{sig.name} did not interrupt")
    except KeyboardInterrupt:
        pass
    assert signal.getsignal(sig) == before


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # Python's "Exception ignored"
def test_an_interrupt_python_drops_is_still_counted() -> None:
    with sigterm_as_keyboard_interrupt():
        seen = interrupts()
        for signum in (signal.SIGTERM, signal.SIGINT):
            interrupt_in_a_weakref_callback(signum)  # no KeyboardInterrupt reaches here
        assert interrupts() == seen + 2


def test_a_sigterm_while_children_start_is_held_until_they_have() -> None:
    reached = []
    with sigterm_as_keyboard_interrupt():
        try:
            with sigint_blocked_for_children():
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(10_000):
                    pass
                reached.append(True)  # the block ran to its end
        except KeyboardInterrupt:
            reached.append("raised at the end")
    assert reached == [True, "raised at the end"]


def test_an_interrupt_python_drops_prints_nothing_and_other_dropped_errors_still_print() -> None:
    """A helper's Ctrl-C while matplotlib drew a campaign's plots printed Python's "Exception ignored ... Traceback
    ... KeyboardInterrupt" page before the package's one line (2 runs of 7)."""
    import subprocess
    import sys
    import textwrap
    from pathlib import Path

    script = textwrap.dedent("""
        import signal, weakref
        from helpers.interrupts import interrupt_in_a_weakref_callback
        from tpee_ompl.signals import interrupts, sigterm_as_keyboard_interrupt
        class Node: pass
        def fail(_ref): raise ValueError("a real error in a callback")
        with sigterm_as_keyboard_interrupt():
            interrupt_in_a_weakref_callback(signal.SIGINT)
            node = Node(); ref = weakref.ref(node, fail); del node
        print("interrupts", interrupts())
    """)
    tests = Path(__file__).parent
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tests), str(tests.parent)])}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, env=env)
    assert done.returncode == 0 and "interrupts 1" in done.stdout
    assert "KeyboardInterrupt" not in done.stderr
    assert "a real error in a callback" in done.stderr
