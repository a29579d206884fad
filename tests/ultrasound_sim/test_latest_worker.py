"""The imaging thread works on the newest pose only, survives a failing frame, and stops."""

import threading

from ultrasound_sim.latest_worker import LatestWorker

WAIT = 10.0  # s: only a broken worker waits this long


def test_an_item_offered_while_one_waits_replaces_it():
    busy, release, done = threading.Event(), threading.Event(), threading.Event()
    seen = []

    def job(item):
        seen.append(item)
        if item == 'first':
            busy.set()
            release.wait(WAIT)
        if item == 'newest':
            done.set()

    worker = LatestWorker(job, on_error=lambda error: None)
    worker.offer('first')
    assert busy.wait(WAIT)
    for item in ('stale', 'older', 'newest'):  # offered while the first is still being made
        worker.offer(item)
    release.set()
    assert done.wait(WAIT)
    assert seen == ['first', 'newest'] and worker.replaced == 2
    assert worker.close()


def test_a_job_that_raises_is_reported_and_the_next_item_is_made():
    errors, failed, done = [], threading.Event(), threading.Event()

    def job(item):
        if item == 'bad':
            raise ValueError('no frame')
        done.set()

    def on_error(error):
        errors.append(error)
        failed.set()

    worker = LatestWorker(job, on_error=on_error)
    worker.offer('bad')
    assert failed.wait(WAIT)  # taken before the good one could replace it
    worker.offer('good')
    assert done.wait(WAIT)
    assert [str(error) for error in errors] == ['no frame']
    assert worker.close()  # the thread ended


def test_the_start_hook_runs_first_in_the_workers_own_thread():
    started, done = [], threading.Event()
    worker = LatestWorker(lambda item: done.set(), on_error=lambda error: None,
                          on_start=lambda: started.append(threading.get_native_id()))
    worker.offer('item')
    assert done.wait(WAIT)
    assert started == [worker._thread.native_id] != [threading.get_native_id()]
    assert worker.close()
