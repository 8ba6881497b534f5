"""A study's cells on other processes and on a Dask cluster give the default's results, bit for bit."""

import json

import pytest

from lv3d.experiment.executor import DaskExecutor, LocalExecutor, make_executor
from lv3d.experiment.runner import run_study

from test_reliability import _baseline_study, _records  # noqa: E402  (tests/experiment is on sys.path)

pytest.importorskip("distributed")


def _programs(out):
    return {p.relative_to(out).as_posix(): p.read_text() for p in sorted((out / "programs").rglob("*")) if p.is_file()}


def test_local_processes_and_a_local_dask_cluster_give_the_default_results(tmp_path):
    config, sets = _baseline_study(tmp_path)
    run_study(config, tmp_path / "default", sets, progress=False)
    with LocalExecutor(2) as pool:  # two processes of this machine
        run_study(config, tmp_path / "pool", sets, progress=False, executor=pool)
    dask = DaskExecutor(workers=2)  # a cluster of two worker processes on this machine
    try:
        run_study(config, tmp_path / "dask", sets, progress=False, executor=dask)
    finally:
        dask.close()
    want = _records(tmp_path / "default")
    assert len(want) == 9 and _records(tmp_path / "pool") == want and _records(tmp_path / "dask") == want


def test_lv3d_cells_and_facts_on_dask_match_the_default(tmp_path, tiny_config, fake_world):
    """Facts and lv3d cells (their programs come back to this process, which writes them) on a Dask cluster
    of threads of this process, where the test's stand-in learner and pipeline are in force."""
    sets = ["systems=[lv3d-rgbd, lv3d-rgb, tree-rgbd]"]
    run_study(tiny_config, tmp_path / "default", sets, progress=False)
    dask = DaskExecutor(workers=2, processes=False)
    try:
        run_study(tiny_config, tmp_path / "dask", sets, progress=False, executor=dask)
    finally:
        dask.close()
    assert _records(tmp_path / "dask") == _records(tmp_path / "default")
    assert _programs(tmp_path / "dask") == _programs(tmp_path / "default") != {}
    facts = lambda out: {p.name: json.loads(p.read_text()) for p in (out / "facts").rglob("s*.json")}  # noqa: E731
    assert facts(tmp_path / "dask") == facts(tmp_path / "default")


def test_an_unreachable_scheduler_is_one_line():
    from lv3d.errors import InputError

    with pytest.raises(InputError, match="--address: cannot reach the Dask scheduler at tcp://127.0.0.1:9"):
        DaskExecutor("tcp://127.0.0.1:9", timeout="1s")
    with pytest.raises(InputError, match="--executor: unknown executor 'spark'"):
        make_executor("spark")
