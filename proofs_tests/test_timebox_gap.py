"""A signal delivered while :func:`langur.timebox._limited` installs its handler and arms its timer
(the gap before its ``try``): the limit's own expiry there is still a ``TimeoutError``, and an
exception from elsewhere (an outer limit of the other timer firing then) still disarms the timer and
puts the old handler back.  Before, both escaped the ``finally``: a command printed an uncaught
``_Expired`` traceback under load (test_hostile's ``show`` past its budget, seen by split14).

The gap is hit deterministically: timebox's ``setitimer`` is wrapped so that the arming call itself
delivers the signal (the handler just installed is called) or raises the outer exception."""

import signal
import sys
import time

import pytest

from langur import timebox


class Outer(Exception):
    """Stands for an outer limit's exception, raised in the gap."""


@pytest.fixture
def clean_alarm():
    before = signal.getsignal(signal.SIGALRM)
    yield before
    signal.setitimer(signal.ITIMER_REAL, 0)
    signal.signal(signal.SIGALRM, before)


def _arming(monkeypatch, then):
    real = timebox.signal.setitimer  # (timebox's own: ``_signal``, which ``signal`` wraps)

    def setitimer(which, seconds, interval=0.0):
        out = real(which, seconds, interval)
        if which == signal.ITIMER_REAL and seconds > 0 and interval == 0.05:  # _limited arming its timer
            then()
        return out

    monkeypatch.setattr(timebox.signal, "setitimer", setitimer)


def test_the_limit_firing_as_it_is_armed_is_a_timeout(monkeypatch, clean_alarm):
    def deliver():  # what a tiny limit does: the signal arrives before the next statement
        signal.getsignal(signal.SIGALRM)(signal.SIGALRM, sys._getframe())

    _arming(monkeypatch, deliver)
    with pytest.raises(TimeoutError):
        timebox._limited(lambda: "ran", 5.0, signal.ITIMER_REAL, signal.SIGALRM, time.monotonic, "s")
    monkeypatch.undo()
    assert signal.getsignal(signal.SIGALRM) == clean_alarm
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_an_outer_exception_in_the_gap_leaves_no_timer_and_no_handler(monkeypatch, clean_alarm):
    def outer():
        raise Outer()

    _arming(monkeypatch, outer)
    with pytest.raises(Outer):
        timebox._limited(lambda: "ran", 5.0, signal.ITIMER_REAL, signal.SIGALRM, time.monotonic, "s")
    monkeypatch.undo()
    # nothing left behind to raise an _Expired later, anywhere
    assert signal.getsignal(signal.SIGALRM) == clean_alarm
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_limits_still_work_after_the_gap_tests(clean_alarm):
    with pytest.raises(TimeoutError):
        timebox.run_with_timeout(lambda: time.sleep(2), 0.2)
    assert timebox.run_with_timeout(lambda: 7, 1.0) == 7
    assert signal.getsignal(signal.SIGALRM) == clean_alarm
