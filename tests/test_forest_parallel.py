"""The forest through joblib: the same trees on any number of threads and on a dask
cluster's workers (joblib.parallel_config(backend="dask"))."""

from __future__ import annotations

import numpy as np
import pytest
from joblib import parallel_config

from sk_rtw import RTWProximityForest

from .test_forest import three_classes


def _trees(forest):
    return [(t.n_nodes_, str(t.root_.split)) for t in forest.trees_]


def test_joblib_threads_from_parallel_config_give_the_same_forest():
    X, y = three_classes()
    test, _ = three_classes(seed=5)
    one = RTWProximityForest(n_trees=8, random_state=3).fit(X, y)
    with parallel_config(backend="threading", n_jobs=2):
        two = RTWProximityForest(n_trees=8, random_state=3).fit(X, y)
    assert _trees(one) == _trees(two)
    np.testing.assert_array_equal(one.predict_proba(test), two.predict_proba(test))


@pytest.mark.slow
def test_a_dask_cluster_trains_the_same_forest():
    distributed = pytest.importorskip("distributed")
    X, y = three_classes()
    test, _ = three_classes(seed=5)
    local = RTWProximityForest(n_trees=6, random_state=1).fit(X, y)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:  # fmt: skip
        with parallel_config(backend="dask"), distributed.get_task_stream(client) as stream:
            remote = RTWProximityForest(n_trees=6, random_state=1, n_jobs=2).fit(X, y)
    workers = {task["worker"] for task in stream.data}
    assert len(stream.data) >= 1 and workers  # the trees were grown on the workers
    assert _trees(remote) == _trees(local)
    np.testing.assert_array_equal(remote.predict_proba(test), local.predict_proba(test))
