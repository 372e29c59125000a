"""The configuration layer: written signatures, settings resolved once, a user's own
averaging method, and help() that says what runs."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import numpy as np
import pytest
from sklearn.base import BaseEstimator, clone
from sklearn.model_selection import GridSearchCV

import sk_rtw
from sk_rtw import RTW, RTWAverager, RTWKMeans, RTWNearestCentroid
from sk_rtw._settings._resolve import _cell
from sk_rtw.align import KNOBS, PRESETS
from sk_rtw.baselines import dba_average
from sk_rtw.methods import METHODS, AveragingMethod, EngineMethod
from sk_rtw.utils._constraints import Interval
from sk_rtw.utils._params import Parameter, declare_parameters

METHODS_PAGE = Path(__file__).resolve().parents[1] / "docs" / "user_guide" / "methods.md"
ESTIMATORS = [
    cls
    for cls in vars(sk_rtw).values()
    if isinstance(cls, type) and issubclass(cls, BaseEstimator)
    and not issubclass(cls, AveragingMethod)
]  # fmt: skip
DECLARED = [*ESTIMATORS, *METHODS.values()]
#: The estimators that average (a method and a preset): the proximity forest does not.
AVERAGING = [cls for cls in ESTIMATORS if "method" in cls._declaration.defaults]


def test_every_public_estimator_and_method_is_checked():
    names = {cls.__name__ for cls in DECLARED}
    assert {"RTWAverager", "RTWNearestCentroid", "RTWKMeans", "TTWNearestCentroid",
            "NTWAverager", "RTWProximityForest", "RTW", "TTW", "NTW", "DBA"} <= names  # fmt: skip


@pytest.mark.parametrize("cls", DECLARED, ids=lambda c: c.__name__)
def test_every_written_signature_is_its_declaration(cls):
    assert "__init__" in vars(cls), "the class writes its own __init__"
    written = inspect.signature(cls.__init__)
    declared = cls._declaration.signature()
    assert [(p.name, p.kind, p.default) for p in written.parameters.values()] == [
        (p.name, p.kind, p.default) for p in declared.parameters.values()
    ]
    # scikit-learn's rule: every parameter stored unchanged
    estimator = cls()
    assert estimator.get_params(deep=False) == cls._declaration.defaults


def test_a_signature_that_drifts_from_its_declaration_is_refused_at_definition():
    width = Parameter("width", (Interval(int, 1),), "Width.")
    with pytest.raises(TypeError, match="differs from its declared parameters"):

        @declare_parameters([width], {"width": 3}, positional=0)
        class Drifted(BaseEstimator):
            def __init__(self, *, width=4):
                self.width = width

    with pytest.raises(TypeError, match="must write its own __init__"):

        @declare_parameters([width], {"width": 3}, positional=0)
        class Unwritten(BaseEstimator):
            pass


def test_an_unknown_keyword_still_says_where_the_setting_belongs():
    with pytest.raises(TypeError, match=r"method=RTW\(hidden_size=\.\.\.\)"):
        RTWNearestCentroid(hidden_size=64)
    with pytest.raises(TypeError, match="n_components is a setting of TTW"):
        RTW(n_components=3)


def test_dba_average_defaults_are_the_dba_knobs():
    defaults = {name: p.default for name, p in inspect.signature(dba_average).parameters.items()}
    for knob in ("max_iter", "tol"):
        assert defaults[knob] == KNOBS[knob].defaults["dba"], knob


# ------------------------------------------------------------------ resolved once
def test_a_fit_configures_its_method_once_and_the_engine_gets_that_configuration(monkeypatch):
    calls, received = [], []
    configure, fit_groups = EngineMethod.configure, EngineMethod.fit_groups

    def counting_configure(self, context):
        calls.append(context.preset)
        return configure(self, context)

    def recording_fit_groups(self, collection, codes, seeds, config, context, starts=None):
        received.append(config)
        return fit_groups(self, collection, codes, seeds, config, context, starts)

    monkeypatch.setattr(EngineMethod, "configure", counting_configure)
    monkeypatch.setattr(EngineMethod, "fit_groups", recording_fit_groups)
    X = np.sin(np.linspace(0, 6, 30))[None] + 0.1 * np.arange(8)[:, None]
    y = np.repeat([0, 1], 4)
    RTWNearestCentroid(method=RTW(n_epochs=2, hidden_size=8), random_state=0).fit(X, y)
    assert calls == ["class-means"]
    assert received and all(c.hidden_size == 8 and c.n_epochs == 2 for c in received)
    calls.clear()
    RTWKMeans(2, method=RTW(n_epochs=2), max_iter=3, random_state=0).fit(X)
    assert calls == ["class-means"]  # once per fit, not once per round


def test_a_bad_method_setting_stops_the_fit_before_any_work(monkeypatch):
    import sk_rtw.estimators._averager as averager

    def no_work(*args, **kwargs):  # pragma: no cover - reached only on failure
        raise AssertionError("the series were read before the settings were checked")

    monkeypatch.setattr(averager, "check_series_collection", no_work)
    with pytest.raises(ValueError, match="hidden_size must be"):
        RTWNearestCentroid(method=RTW(hidden_size=0)).fit(np.zeros((4, 10)), [0, 0, 1, 1])


# ------------------------------------------------------------------ a user's own method
def user_method_namespace() -> dict:
    """The example of the user guide's methods page, run as written."""
    code = re.findall(r"```python\n(.*?)```", METHODS_PAGE.read_text(), re.S)[-1]
    namespace: dict = {}
    exec(compile(code, str(METHODS_PAGE), "exec"), namespace)
    return namespace


def test_a_users_own_method_works_in_every_estimator_in_clone_and_in_a_search():
    ns = user_method_namespace()
    Medoid, X, y = ns["Medoid"], ns["X"], np.asarray(ns["y"])
    assert Medoid.__name__ not in METHODS
    for estimator in (
        RTWAverager(method=Medoid(window=0.1)),
        RTWNearestCentroid(method=Medoid(window=0.1)),  # the default choice of centroids
        RTWKMeans(2, method=Medoid(), random_state=0),
    ):
        fitted = estimator.fit(X, y)
        assert fitted.method_ == "Medoid" if hasattr(fitted, "method_") else True
        copy = clone(estimator)
        assert copy.get_params()["method__window"] == estimator.get_params()["method__window"]
        assert copy.method is not estimator.method
    clf = RTWNearestCentroid(method=Medoid(), n_centroids=1, dtw_window=None).fit(X, y)
    assert clf.predict(X).tolist() == y.tolist()
    means = np.asarray(clf.means_)
    assert any(np.allclose(means[0], x[:, None]) for x in X[:3])  # a medoid is a series
    search = GridSearchCV(
        RTWNearestCentroid(method=Medoid(), n_centroids=1, dtw_window=None),
        {"method__window": [None, 0.2]}, cv=2,
    ).fit(X, y)  # fmt: skip
    assert search.best_estimator_.method.window in (None, 0.2)
    with pytest.raises(ValueError, match="window must be in"):
        RTWNearestCentroid(method=Medoid(window=2.0)).fit(X, y)


# ------------------------------------------------------------------ help() says what runs
@pytest.mark.parametrize("cls", AVERAGING, ids=lambda c: c.__name__)
def test_help_lists_the_default_methods_settings_under_every_preset(cls):
    defaults = cls._declaration.defaults
    method, first = defaults["method"], defaults["preset"]
    doc = inspect.getdoc(cls)
    presets = [first, *(p for p in PRESETS if p != first)]
    header = next(line for line in doc.splitlines() if line.startswith("setting "))
    assert header.split() == ["setting", *(f'preset="{p}"' for p in presets)]
    rows = {
        line.split()[0].strip("`"): line.split()
        for line in doc.splitlines()
        if line.startswith("``")
    }
    for knob in KNOBS.values():
        if method not in knob.defaults:
            assert knob.name not in rows, knob.name
            continue
        if knob.name == "output_length":
            continue
        expected = [_cell(PRESETS[p].defaults(method)[knob.name]) for p in presets]
        assert rows[knob.name][1:] == expected, knob.name
    assert f'method="{method}"' in doc
