"""``TimeLimited``: a routine that may not return runs in a forked child with a limit."""

import os
import time

import pytest

from lmi_suspension.mu.timelimit import TimeLimited

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")


def _sleep_then(seconds, value):
    time.sleep(seconds)
    return value


def _die():
    os._exit(3)


def test_results_come_back_and_one_child_serves_every_call():
    with TimeLimited(os.getpid, seconds=5.0) as call:
        first, second = call(), call()
    assert first == second != os.getpid()      # ran in a child, the same one twice


def test_a_call_past_the_limit_is_stopped_and_the_next_call_works():
    with TimeLimited(_sleep_then, seconds=0.3) as call:
        t0 = time.perf_counter()
        with pytest.raises(TimeoutError, match="within 0.3 s"):
            call(60.0, "never")
        # the child is killed at the limit, not waited for (60 s)
        assert time.perf_counter() - t0 < 5.0
        assert call(0.0, "after") == "after"


def test_errors_and_a_dying_child_reach_the_caller_typed():
    with TimeLimited(int, seconds=5.0) as call:
        with pytest.raises(RuntimeError, match="ValueError"):
            call("not a number")
        assert call("12") == 12                   # the child survived the error
    with TimeLimited(_die, seconds=5.0) as call:
        with pytest.raises(ChildProcessError):
            call()


def test_close_ends_the_child():
    call = TimeLimited(os.getpid, seconds=5.0)
    pid = call()
    call.close()
    with pytest.raises(ChildProcessError):        # reaped: no such child any more
        os.waitpid(pid, os.WNOHANG)


@pytest.mark.parametrize("seconds", [0.0, -1.0, float("nan")])
def test_a_limit_that_is_not_positive_is_refused(seconds):
    with pytest.raises(ValueError, match="seconds"):
        TimeLimited(os.getpid, seconds=seconds)


def test_closing_one_does_not_wait_for_another_ones_child():
    """A child forked by one ``TimeLimited`` inherits the other's pipe, which then never
    reads EOF: closing must not wait for the child to notice (it is killed)."""
    a, b = TimeLimited(os.getpid, seconds=5.0), TimeLimited(os.getpid, seconds=5.0)
    a(), b()
    t0 = time.perf_counter()
    a.close()
    assert time.perf_counter() - t0 < 2.0
    b.close()


def test_an_interrupted_call_leaves_no_stale_reply():
    """A call interrupted in the parent (here by a timer signal, as by Ctrl-C) is still
    running in the child: the next call must not read its reply, and closing must not
    wait for it."""
    import signal

    class Interrupted(Exception):
        pass

    def interrupt(*_):
        raise Interrupted

    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        with TimeLimited(_sleep_then, seconds=30.0) as call:
            signal.setitimer(signal.ITIMER_REAL, 0.3)
            with pytest.raises(Interrupted):
                call(3.0, "stale")
            t0 = time.perf_counter()
            assert call(0.0, "fresh") == "fresh"
            assert time.perf_counter() - t0 < 2.0
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_an_unpicklable_result_is_an_error_naming_it():
    with TimeLimited(lambda: (lambda: None), seconds=5.0) as call:
        with pytest.raises(RuntimeError, match="pickle|Pickl"):
            call()
