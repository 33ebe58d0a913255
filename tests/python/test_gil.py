"""Long work releases the GIL: another Python thread keeps running meanwhile."""
import threading
import time

import texel


def ticks_during(work):
    done = threading.Event()

    def run():
        work()
        done.set()

    t = threading.Thread(target=run)
    t.start()
    ticks = 0
    while not done.is_set():
        ticks += 1
        time.sleep(0.001)
    t.join()
    return ticks


def test_reference_synthesis_releases_the_gil():
    # ~0.5 s of synthesis (4 m of pink noise on the tpad grid: 755,000 samples,
    # chirp-z); with the GIL held the main thread could not tick at all.
    assert ticks_during(lambda: texel.reference("pink", length_mm=4000)) > 20


def test_encode_releases_the_gil():
    # An encode takes ~15 ms now: twenty of them keep the worker busy long
    # enough to count ticks.
    m = texel.render(seed=3)
    assert ticks_during(lambda: [texel.encode(m) for _ in range(20)]) > 20
