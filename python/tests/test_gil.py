"""Long Rust calls release the GIL: another Python thread makes progress meanwhile.

Progress is counted, not timed: with the switch interval raised to 1000 s, a thread holding the
GIL is never preempted, so while the worker is inside a call that holds the GIL the main thread
cannot run a single iteration (the control below checks exactly that with a Python busy loop).
A call that releases the GIL lets the main thread count."""

import sys
import threading
import time

import pytest

import restitution as rs
from conftest import DATA


def progress_during(work):
    """Iterations the main thread completes while `work` runs in another thread."""
    entered = threading.Event()
    state = {"inside": False, "result": None}

    def worker():
        state["inside"] = True
        entered.set()
        state["result"] = work()
        state["inside"] = False

    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        entered.wait()
        count = 0
        while state["inside"]:
            count += 1
            time.sleep(1e-4)  # releases the GIL so the worker can finish
        t.join()
    finally:
        sys.setswitchinterval(old)
    return count, state["result"]


def test_control_a_call_that_holds_the_gil_gives_no_progress():
    def busy():
        end = time.perf_counter() + 0.2
        while time.perf_counter() < end:
            pass

    count, _ = progress_during(busy)
    assert count == 0


def test_fit_releases_the_gil():
    path = str(DATA / "fig7_nylon.csv")
    # --exact: about 0.25 s of ODE integrations (README), long enough to be seen from outside.
    with pytest.warns(rs.DataWarning):
        count, r = progress_during(lambda: rs.fit(path, "nylon", model="vm", exact=True))
    assert count > 0
    with pytest.warns(rs.DataWarning):
        serial = rs.fit(path, "nylon", model="vm", exact=True)
    assert r.to_dict() == serial.to_dict()


def test_array_evaluation_releases_the_gil():
    import numpy as np

    kappa = np.full(20_000, 5.0)
    count, e = progress_during(lambda: rs.e_of_kappa(kappa, method="dop853"))
    assert count > 0
    assert np.all(e == e[0])
