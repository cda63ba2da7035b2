"""Running sweeps: serial vs Dask row for row, resume after an interruption, a worker
killed mid-run, and the results folder's rules."""

import os
import signal

import numpy as np
import pytest

from taut.errors import SweepError
from taut.sweep import read_results, run_sweep, sweep_from_mapping


def _serial(spec, tmp_path, name="serial"):
    res = run_sweep(spec, tmp_path / name, workers=0)
    assert res.success and res.status == "ok"
    return read_results(tmp_path / name)


def test_serial_run_writes_every_point_once_with_metadata(fk_spec, tmp_path):
    spec = fk_spec(scale={"range": [0.6, 1.0], "num": 5}, stretch_angle=[0, 30, 60, 90],
                   stretch=1.2)
    cols, meta = _serial(spec, tmp_path)
    np.testing.assert_array_equal(cols["point"], np.arange(20))
    assert meta["sweep_digest"] == spec.digest and meta["sweep_task"] == "fk_stability_map"
    assert meta["taut_version"]


def test_interrupted_run_resumes_without_duplicates(fk_spec, tmp_path, same_rows):
    spec = fk_spec(scale={"range": [0.6, 1.0], "num": 8}, stretch_angle=[0, 45, 90, 135, 170],
                   stretch=1.2)                       # 40 points, chunks of 16
    calls = []

    def stop_after_first_chunk(done, total):
        calls.append(done)
        if done >= 16:
            raise KeyboardInterrupt

    res = run_sweep(spec, tmp_path / "run", workers=0, progress=stop_after_first_chunk)
    assert not res.success and res.status == "interrupted" and res.path is None
    with pytest.raises(SweepError) as err:            # same sweep, no --resume
        run_sweep(spec, tmp_path / "run", workers=0)
    assert err.value.field == "out"
    res = run_sweep(spec, tmp_path / "run", workers=0, resume=True)
    assert res.success and res.chunks_reused == 1 and res.chunks_run == 2
    cols, _ = read_results(tmp_path / "run")
    np.testing.assert_array_equal(cols["point"], np.arange(40))
    same_rows(cols, _serial(spec, tmp_path)[0])


def test_a_folder_of_another_sweep_is_refused(fk_spec, tmp_path):
    run_sweep(fk_spec(scale=[0.8, 0.9]), tmp_path / "run", workers=0)
    with pytest.raises(SweepError) as err:
        run_sweep(fk_spec(scale=[0.8, 0.95]), tmp_path / "run", workers=0, resume=True)
    assert err.value.field == "out" and "different sweep" in err.value.problem


def test_limit_keeps_the_first_points_and_a_full_resume_reuses_them(fk_spec, tmp_path, same_rows):
    spec = fk_spec(scale={"range": [0.6, 1.0], "num": 40})
    res = run_sweep(spec, tmp_path / "run", workers=0, limit=20)
    assert res.rows == 20 and res.chunks_run == 2
    res = run_sweep(spec, tmp_path / "run", workers=0, resume=True)
    assert res.rows == 40 and res.chunks_reused == 2 and res.chunks_run == 1
    same_rows(read_results(tmp_path / "run")[0], _serial(spec, tmp_path)[0])


@pytest.mark.slow
def test_two_worker_cluster_gives_the_serial_rows(fk_spec, tmp_path, same_rows):
    pytest.importorskip("distributed")
    spec = fk_spec(scale={"range": [0.6, 1.0], "num": 10}, stretch_angle=[0, 40, 80, 120, 160],
                   stretch=1.25, jitter=[0.0, 3.0])
    res = run_sweep(spec, tmp_path / "dask", workers=2)
    assert res.success and res.chunks_run == 7
    same_rows(read_results(tmp_path / "dask")[0], _serial(spec, tmp_path)[0])


@pytest.mark.slow
def test_a_killed_worker_loses_and_duplicates_nothing(fk_spec, tmp_path, same_rows):
    distributed = pytest.importorskip("distributed")
    import logging

    spec = fk_spec(scale={"range": [0.5, 1.0], "num": 30}, stretch_angle=[0, 30, 60, 90, 120, 150],
                   stretch=1.25)                      # 180 points, 12 chunks
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0", silence_logs=logging.ERROR) as cluster:
        with distributed.Client(cluster) as client:   # closed before the sweep's own client
            pids = list(client.run(os.getpid).values())
        killed = []

        def kill_one(done, total):
            if done >= 16 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        res = run_sweep(spec, tmp_path / "dask", scheduler=cluster.scheduler_address,
                        progress=kill_one)
    assert killed and res.success
    cols, _ = read_results(tmp_path / "dask")
    np.testing.assert_array_equal(cols["point"], np.arange(180))
    same_rows(cols, _serial(spec, tmp_path)[0])


def _dask_logs(client):
    """Every debugging log Dask keeps in the sweep's process (a local cluster's scheduler
    runs there): name -> deque."""
    sched = client.cluster.scheduler
    logs = {"transitions": sched.transition_log,
            "client stream": client.scheduler_comm.recent_message_log}
    logs.update({f"event topic {k}": t.events for k, t in sched._broker._topics.items()})
    logs.update({f"stream to {k}": b.recent_message_log
                 for k, b in {**sched.stream_comms, **sched.client_comms}.items()})
    return logs


@pytest.mark.slow
def test_the_clients_dask_logs_stay_bounded_however_many_chunks(examples_dir, tmp_path,
                                                                monkeypatch):
    """Issue 32: the 10^7-point run's client grew ~10 kB a chunk: Dask's debugging logs
    (1,000 entries each by default: task specs of recent messages, an event per submitted
    chunk) live in the client's process with a local cluster. A run of 3x as many
    chunks as the bound leaves every log within it, and some log full (so the bound, not
    the run's length, is what limits it)."""
    pytest.importorskip("distributed")
    from taut.sweep import runner

    opened = []

    def keep(workers, scheduler):
        client = open_client(workers, scheduler)
        opened.append(client)
        return client

    open_client = runner._open_client
    monkeypatch.setattr(runner, "_open_client", keep)
    n = 3 * runner.DASK_LOG_ENTRIES
    seen = {}

    def inspect(done, total):
        if done == total:
            seen.update({k: (len(v), v.maxlen) for k, v in _dask_logs(opened[0]).items()})

    spec = sweep_from_mapping({"task": "fk_stability_map", "chunk_size": 1,
                               "base": "examples/sheet/example2_r2_r4_353mm.yaml",
                               "parameters": {"scale": {"range": [0.6, 1.0], "num": n}}},
                              examples_dir.parent)
    assert run_sweep(spec, tmp_path / "dask", workers=1, progress=inspect).success
    assert seen and all(size <= runner.DASK_LOG_ENTRIES for size, _ in seen.values()), seen
    assert max(size for size, _ in seen.values()) == runner.DASK_LOG_ENTRIES, seen


@pytest.mark.slow
def test_a_scheduler_that_does_not_answer_is_reported_quickly(fk_spec, tmp_path):
    pytest.importorskip("distributed")
    import time

    t0 = time.perf_counter()
    with pytest.raises(SweepError) as err:
        run_sweep(fk_spec(scale=[1.0]), tmp_path / "x", scheduler="tcp://127.0.0.1:9")
    assert err.value.field == "scheduler"
    assert time.perf_counter() - t0 < 30
    assert not (tmp_path / "x").exists()              # nothing written
