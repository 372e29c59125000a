"""The estimators' parameters, declared once: what each accepts and means.

A handful of parameters that mean something for every averaging method; every setting
of a method (the engine's knobs, DBA's iterations) lives in the method object
(``method=RTW(hidden_size=64)``, searchable as ``method__hidden_size``).
"""

from __future__ import annotations

from dataclasses import replace

from .._settings import DEVICE_PARAMETER, PRESET_PARAMETER, owners, settings_table
from ..methods import METHODS, get_method
from ..methods._registry import method_parameter
from ..representations import REPRESENTATIONS
from ..utils._common_params import DTW_WINDOW as BAND
from ..utils._common_params import MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._constraints import Constant, InstanceOf, Interval, Options
from ..utils._params import Parameter, doc_indent, indent, wrap
from ._choice import DEFAULT_CHOICE, AutoChoice

METHOD = method_parameter(
    'Averaging method: "rtw", "ttw", "ntw", "dba" (DTW barycenter averaging with Fréchet '
    "means, any manifold), or a method object: a shipped one holding settings, e.g. "
    "RTW(hidden_size=64), searchable as method__hidden_size, or an AveragingMethod of your "
    'own. A name is the object with every setting "auto" (the preset\'s value).'
)
N_CENTROIDS = Parameter(
    "n_centroids",
    (Interval(int, 1), Interval(float, 0.0, 1.0, closed="right"), Options(("auto",))),
    "Centroids per class: an integer is a count for every class (at most its series), a "
    "float in (0, 1] a fraction of every class, rounded up (1.0: every series is a "
    "centroid, 1-NN DTW within the band), so that large classes get more centroids. Each "
    "class is split into its parts by k-medoids on the DTW matrix of its series (band "
    "``dtw_window``) and every part of several series is averaged once; a part of one "
    'series is that series. "auto": the preset\'s value, as for every "auto" of the '
    "package: chosen from the training data with the band (fitted ``n_centroids_``, the "
    'scores in ``selection_``) under "class-means" and "alignment", one mean per class '
    'under "paper".',
)
DTW_WINDOW = replace(
    BAND.with_auto(),
    doc="Sakoe-Chiba band of every DTW of the fit (the DTW start of RTW, TTW and NTW, DBA, "
    "the partition into centroids) and of prediction, its radius as a fraction of the "
    "shorter series' length; None: no band. \"auto\": the preset's value: chosen from the "
    'training data with the centroids (fitted ``dtw_window_``) under "class-means" and '
    '"alignment", no band under "paper".',
)
REPRESENTATION = Parameter(
    "representation",
    (Options((*REPRESENTATIONS, "auto")),),
    'What is averaged and compared: "raw" the series, "velocity" their tangent velocity '
    "(sk_rtw.tangent_velocity: the manifold's derivative series, Euclidean vectors; the "
    "centroids are then velocity series), applied to every series the estimator is given, "
    'in fit and after. "auto": chosen with the band and the centroids (both chosen on the '
    "series and on their velocity; the velocity where its choice classifies the held-out "
    "training series better by a standard error; fitted ``representation_`` and "
    '``selection_["representation"]``); the series where nothing is chosen. "raw" is the '
    'default because "auto" won 3 points on one half of the UCR development archive and '
    "nothing on three others (UCR page).",
)
CHOICE = Parameter(
    "choice",
    (
        Constant(None, "AutoChoice(), the measured default"),
        InstanceOf("AutoChoice", "an AutoChoice", (AutoChoice,)),
    ),
    'What every "auto" value of the estimator chooses from, and the evidence needed to '
    "leave its prior (sk_rtw.AutoChoice: candidate bands, centroids and representations, "
    "the prior, z_threshold; searchable as choice__z_threshold, or a list of objects in a "
    f"grid). The default: {DEFAULT_CHOICE.describe()}.",
)
TEMPERATURE = Parameter(
    "temperature",
    (Interval(float, 0.0, closed="neither"), Options(("fit",))),
    'Scale of the distances in predict_proba, softmax(-d / temperature). "fit": fitted in '
    "fit by minimising the log-loss of the training series' held-out distances (raw DTW "
    "distances are in the data's units: a fixed scale saturates or flattens); predictions "
    "do not depend on it.",
)
N_CLUSTERS = Parameter("n_clusters", (Interval(int, 1),), "Number of clusters.")
N_INIT = Parameter(
    "n_init",
    (Interval(int, 1),),
    "k-means++ seedings; the clustering with the lowest inertia is kept.",
)
MAX_ITER = Parameter("max_iter", (Interval(int, 1),), "Most assignment/update rounds per seeding.")
TOL = Parameter(
    "tol",
    (Interval(float, 0.0),),
    "Relative improvement of the objective that counts as progress, as for every tol of "
    "the package; here the objective is the inertia and a seeding stops at the first "
    "round below it (or when no series changes cluster). The averaging method's own tol "
    "(method=RTW(tol=...)) is the same rule for its own objective.",
)

#: The parameters of :class:`RTWAverager`, in signature order, with its defaults.
AVERAGER_PARAMETERS = (
    MANIFOLD, METHOD, PRESET_PARAMETER, N_CENTROIDS, DTW_WINDOW, REPRESENTATION, CHOICE,
    N_JOBS, RANDOM_STATE, DEVICE_PARAMETER, VERBOSE,
)  # fmt: skip
AVERAGER_DEFAULTS = {
    "manifold": "euclidean",
    "method": "rtw",
    "preset": "class-means",
    "n_centroids": 1,
    "dtw_window": None,
    "representation": "raw",
    "choice": None,
    "n_jobs": None,
    "random_state": None,
    "device": "cpu",
    "verbose": 0,
}


def setting_hint(name: str) -> str:
    """Where a keyword that is no estimator parameter belongs."""
    methods = owners(name)
    if methods:
        label = METHODS[methods[0]].__name__
        return (
            f"{name} is a setting of the averaging method: pass it there, "
            f"method={label}({name}=...), searchable as method__{name}"
        )
    if name == "averager_params":
        return "the averaging settings are the method object's: method=RTW(...)"
    return "see help() for the parameters"


def set_params_with_hints(estimator, params: dict, set_params) -> None:
    """``BaseEstimator.set_params`` (``set_params``) with two additions.

    A method given by name reaches its settings (``method__n_epochs`` on
    ``method="rtw"``): the name becomes its object, every setting ``"auto"``, which is
    what the name stands for; a keyword that is no parameter says where it belongs.
    """
    nested = any(key.startswith("method__") for key in params)
    if nested and "method" not in params and isinstance(getattr(estimator, "method", None), str):
        estimator.method = get_method(estimator.method)
    own = estimator.get_params(deep=False)
    for key in params:
        name = key.split("__", 1)[0]
        if name not in own:
            raise ValueError(
                f"Invalid parameter {name!r} for estimator {type(estimator).__name__}: "
                f"{setting_hint(name)}. Valid parameters are: {sorted(own)}."
            )
    set_params(**params)


#: Where :func:`document_settings` writes the default method's settings.
SETTINGS_MARKER = "%(method_settings)s"
#: Where :func:`document_settings` writes the default choice's candidates.
CHOICE_MARKER = "%(choice)s"


def settings_notes(method: str, preset: str, chooses: bool = False) -> str:
    """The "Notes" text of an estimator whose defaults are ``method`` and ``preset``: what
    runs, and every setting of the method under each preset (from the knob and preset
    records)."""
    label = METHODS[method].__name__
    text = [
        f'What runs by default: ``method="{method}"``, i.e. :class:`~sk_rtw.{label}` with '
        f'every setting ``"auto"``: the value of the preset (``preset="{preset}"`` unless '
        f"set), listed below; a value given in the method object, "
        f'``method={label}(n_epochs=64)``, replaces it. ``"auto"`` means the preset\'s '
        "value everywhere in the package."
    ]
    if chooses:
        text.append(
            'The estimator\'s own ``"auto"`` values follow the same rule: under "class-means" '
            'and "alignment" the band and the centroids per class are chosen from the '
            'training data (``selection_``); under "paper" one mean per class and no band.'
        )
    wrapped = [line for paragraph in text for line in (*wrap(paragraph), "")]
    return "\n".join([*wrapped, settings_table(method, preset)])


def document_settings(cls):
    """Class decorator (above :func:`~sk_rtw.utils._params.declare_parameters`): the
    docstring's ``%(method_settings)s`` becomes :func:`settings_notes` for the class's
    default method and preset."""
    defaults = cls._declaration.defaults
    chooses = "n_centroids" in defaults
    if cls.__doc__ and SETTINGS_MARKER in cls.__doc__:
        notes = settings_notes(defaults["method"], defaults["preset"], chooses)
        block = indent(notes, doc_indent(cls.__doc__, SETTINGS_MARKER))
        cls.__doc__ = cls.__doc__.replace(SETTINGS_MARKER, block.lstrip())
    if cls.__doc__ and CHOICE_MARKER in cls.__doc__:
        grid = f"The default candidates (``choice=None``): {DEFAULT_CHOICE.describe()}."
        block = indent("\n".join(wrap(grid)), doc_indent(cls.__doc__, CHOICE_MARKER))
        cls.__doc__ = cls.__doc__.replace(CHOICE_MARKER, block.lstrip())
    return cls
