"""Contract suites: every averaging method on every manifold, every preset for every method.

The same assertions for every variant (pyRiemann's one test per classifier x metric,
geomstats' test case per space): means on the manifold, a batch of classes equal to
separate fits, the same bits for the same seed, the same result fields; and one
configuration per preset name, whichever entry point resolves it.

Regenerate the snapshot of the resolved presets after an intended change with
``python -m tests.test_contracts``.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path

import numpy as np
import pytest
from sklearn.base import clone

from sk_rtw import RTW, RTWAverager, RTWKMeans, RTWNearestCentroid, align
from sk_rtw._settings import knobs_markdown, presets_markdown, resolve_knobs
from sk_rtw.align import ENGINE_METHODS, KNOBS, PRESETS, resolve_config, size_config
from sk_rtw.datasets import make_warped_signals
from sk_rtw.methods import METHODS, RESULT_FIELDS, AveragingResult, FitContext, get_method
from sk_rtw.utils import check_series_collection

from .conftest import MANIFOLDS, manifold_id, quick

SNAPSHOT = Path(__file__).parent / "snapshots" / "resolved_presets.json"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "user_guide" / "parameters.md"
ESTIMATORS = (RTWAverager, RTWNearestCentroid, RTWKMeans)


def two_classes(M, length=12):
    a = make_warped_signals(M, 3, length, random_state=1).signals
    b = make_warped_signals(M, 3, length, random_state=2).signals
    return np.concatenate([a, b]), np.repeat([0, 1], 3)


# ------------------------------------------------------------ methods x manifolds
@pytest.mark.parametrize("M", MANIFOLDS, ids=manifold_id)
@pytest.mark.parametrize("name", METHODS)
def test_every_method_on_every_manifold(name, M):
    X, y = two_classes(M)
    estimator = RTWAverager(manifold=M, method=quick(name), random_state=0)
    fitted = estimator.fit(X, y)
    again = clone(estimator).fit(X, y)
    # the same bits for the same seed
    np.testing.assert_array_equal(np.asarray(fitted.means_), np.asarray(again.means_))
    for k, result in enumerate(fitted.alignments_):
        # the same result fields, with the same meaning, for every method
        assert isinstance(result, AveragingResult), [
            f for f in RESULT_FIELDS if not hasattr(result, f)
        ]
        z, n = len(result.mean), int((y == k).sum())
        assert result.mean.shape == (z, *M.point_shape)
        assert result.aligned.shape == (n, z, *M.point_shape)
        assert result.warps.shape == (n, z)
        assert np.all((result.warps >= 0) & (result.warps <= 1))
        np.testing.assert_array_equal(result.warps[:, 0], 0.0)
        if name in ENGINE_METHODS:  # the boundary constraint (paper eq. 2a), by design
            np.testing.assert_array_equal(result.warps[:, -1], 1.0)
        else:  # DBA: the first sample matched with each mean sample
            assert np.all(np.diff(result.warps, axis=1) >= 0)
        assert np.isfinite(result.cost) and result.n_iter >= 0 and result.fit_time >= 0
        assert result.config.method == name and result.manifold == fitted.manifold_
        # means and aligned series on the manifold
        M.validate(result.mean, atol=1e-8)
        M.validate(result.aligned, atol=1e-8)


@pytest.mark.parametrize("M", MANIFOLDS, ids=manifold_id)
@pytest.mark.parametrize("name", METHODS)
def test_a_batch_of_classes_equals_separate_fits(name, M):
    X, y = two_classes(M)
    collection = check_series_collection(X, M)
    method, context, seeds = quick(name), FitContext(preset="class-means"), [11, 22]
    config = method.configure(context)
    batch = method.fit_groups(collection, y, seeds, config, context)
    for g, seed in enumerate(seeds):
        members = np.flatnonzero(y == g)
        (alone,) = method.fit_groups(
            collection.subset(members), np.zeros(len(members), int), [seed], config, context
        )
        np.testing.assert_allclose(batch[g].mean, alone.mean, atol=1e-9)
        np.testing.assert_allclose(batch[g].warps, alone.warps, atol=1e-9)
        assert batch[g].n_iter == alone.n_iter


# ------------------------------------------------------------------ presets x methods
@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("name", ENGINE_METHODS)
def test_align_and_every_estimator_resolve_the_same_configuration(preset, name):
    rng = np.random.default_rng(0)
    X = [rng.standard_normal(n).cumsum() for n in (14, 17, 20, 15)]  # unequal lengths
    method = quick(name, n_epochs=1)
    expected = align(X, method=method, preset=preset, random_state=0).config
    for estimator in (
        RTWAverager(method=method, preset=preset, random_state=0),
        RTWKMeans(1, method=method, preset=preset, max_iter=1, random_state=0),
    ):
        assert estimator.fit(X).alignments_[0].config == expected
    # the output length is the preset's rule for these lengths
    assert expected.output_length == PRESETS[preset].output_length([14, 17, 20, 15])


def resolved_presets() -> dict:
    """Every preset x method, resolved for five series of 30 to 60 samples."""
    lengths = [30, 40, 40, 50, 60]
    out = {}
    for preset in PRESETS:
        for method in METHODS:
            if method in ENGINE_METHODS:
                values = size_config(resolve_config(method, preset, {}), lengths).to_dict()
            else:
                values = resolve_knobs(method, preset, {})
            out[f"{preset}/{method}"] = values
    return out


def test_every_resolved_preset_matches_its_snapshot():
    snapshot = json.loads(SNAPSHOT.read_text())
    resolved = json.loads(json.dumps(resolved_presets()))  # the same JSON types
    assert resolved.keys() == snapshot.keys()
    for key, values in resolved.items():
        changed = {
            k: (snapshot[key].get(k), v) for k, v in values.items() if snapshot[key].get(k) != v
        }
        assert not changed, f"{key}: (snapshot, now) {changed}"


def test_the_docs_tables_are_the_registry():
    text = DOCS.read_text()
    assert presets_markdown() in text, "regenerate the presets table of parameters.md"
    assert knobs_markdown() in text, "regenerate the knobs table of parameters.md"


def test_every_knob_is_a_setting_of_some_method_and_every_preset_value_is_valid():
    for name, knob in KNOBS.items():
        assert knob.methods, name
        for method, value in knob.defaults.items():
            if not (name == "output_length" and value is None):
                assert knob.check(value) == value, (name, method)
    for preset in PRESETS.values():
        for method in METHODS:
            for name, value in preset.defaults(method).items():
                if value is not None or name != "output_length":
                    KNOBS[name].check(value)


# ------------------------------------------------------------------ the estimators' surface
@pytest.mark.parametrize("cls", ESTIMATORS)
def test_a_small_documented_surface(cls):
    names = list(inspect.signature(cls).parameters)
    assert len(names) <= 12
    for name in names:  # every parameter documented from its declaration
        assert f"{name} : " in cls.__doc__, name
    assert "method" in names and "preset" in names


@pytest.mark.parametrize("cls", ESTIMATORS)
def test_every_knob_reachable_and_round_tripping_through_get_set_params_and_clone(cls):
    for name in METHODS:
        method = get_method(name)
        estimator = cls(method=method)
        for knob in method.get_params():
            key = f"method__{knob}"
            assert key in estimator.get_params()
            value = KNOBS[knob].defaults[name]
            value = 3 if value is None else value
            estimator.set_params(**{key: value})
            assert estimator.get_params()[key] == value
        cloned = clone(estimator)
        assert cloned.get_params() == estimator.get_params()
        assert cloned.method is not estimator.method  # a copy, not the same object


def test_method_objects_compare_by_value_and_name_their_settings():
    assert RTW(hidden_size=64) == RTW(hidden_size=64) != RTW(hidden_size=32)
    assert repr(RTW(hidden_size=64)) == "RTW(hidden_size=64)"
    assert get_method("rtw") == RTW()
    with pytest.raises(TypeError, match="n_components is a setting of TTW"):
        RTW(n_components=3)


if __name__ == "__main__":  # regenerate the snapshot after an intended change
    SNAPSHOT.parent.mkdir(exist_ok=True)
    SNAPSHOT.write_text(json.dumps(resolved_presets(), indent=1, sort_keys=True) + "\n")
    print(f"written {SNAPSHOT}")
