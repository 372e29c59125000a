"""What a fresh Python process pays: import, the first call against the next ones, and a
parallel grid search.

Usage::

    python benchmarks/first_call.py                 # every probe, 3 fresh processes each
    python benchmarks/first_call.py --probes align --repeat 5

Every probe runs in fresh interpreters (``sys.executable``), as a user meets the library:

* ``align``: ``import sk_rtw``, then :func:`sk_rtw.align` three times on the same 8
  unit-quaternion series (T = 50 and T = 1,000), the default settings; the first call
  against the median of the other two is the one-time cost;
* ``search``: ``GridSearchCV(RTWNearestCentroid(n_centroids=1, dtw_window=None), cv=3)``
  over RTW's ``hidden_size`` and DBA on aeon's GunPoint (its training split), with
  ``n_jobs=1``, ``n_jobs=2`` (joblib's default process workers) and ``n_jobs=2`` on
  threads (``joblib.parallel_config(backend="threading")``, which starts nothing), each
  searched twice in the same process: the second search reuses the workers;
* ``worker``: what a process worker of a parallel search pays before its first candidate:
  a fresh interpreter imports scikit-learn's model selection (every loky worker does, to
  run ``_fit_and_score``), then sk_rtw, then fits the default classifier on a GunPoint
  fold twice (the first fit against the second is the one-time cost of the fit);
* ``long-search``: the default classifier searched over RTW's ``hidden_size`` x
  ``learning_rate`` and DBA (5 candidates x 3 folds) on ``--dataset`` from ``--data-dir``
  (the development archive's Plane by default), the same three ways.

Prints one Markdown table per probe with the median over ``--repeat`` processes. (The
``split`` probe, which divided the first ``align`` by patching the trainer, is retired:
see ``docs/benchmarks/studies.md``.)
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import machine, positive_int

ALIGN = """
import json, time
t = time.perf_counter()
import sk_rtw
imported = time.perf_counter() - t
import numpy as np
from sk_rtw.datasets import make_warped_signals
out = {"import": imported}
for T in (50, 1000):
    X = np.asarray(make_warped_signals("quaternion", 8, T, random_state=0).signals)
    calls = []
    for _ in range(3):
        t = time.perf_counter()
        sk_rtw.align(X, manifold="quaternion", random_state=0)
        calls.append(time.perf_counter() - t)
    out[T] = calls
print(json.dumps(out))
"""

SEARCH = """
import json, sys, time
from aeon.datasets import load_classification
from joblib import parallel_config
from sklearn.model_selection import GridSearchCV
from sk_rtw import DBA, RTW, RTWNearestCentroid
X, y = load_classification("GunPoint", split="train")
X = X[:, 0, :]
grid = [{"method": [RTW()], "method__hidden_size": [16, 64]}, {"method": [DBA()]}]
times = []
for _ in range(2):
    t = time.perf_counter()
    with parallel_config(backend=sys.argv[2]):
        GridSearchCV(RTWNearestCentroid(n_centroids=1, dtw_window=None, random_state=0),
                     grid, cv=3, n_jobs=int(sys.argv[1])).fit(X, y)
    times.append(time.perf_counter() - t)
print(json.dumps(times))
"""


WORKER = """
import json, time
t = time.perf_counter()
import sklearn.model_selection._validation
t_sklearn = time.perf_counter() - t
t = time.perf_counter()
import sk_rtw
t_sk_rtw = time.perf_counter() - t
from aeon.datasets import load_classification
from sk_rtw import RTW, RTWNearestCentroid
X, y = load_classification("GunPoint", split="train")
X = X[:34, 0, :]
fits = []
for _ in range(2):
    t = time.perf_counter()
    RTWNearestCentroid(method=RTW(hidden_size=16), n_centroids=1, dtw_window=None,
                       random_state=0).fit(X, y[:34])
    fits.append(time.perf_counter() - t)
print(json.dumps({"sklearn": t_sklearn, "sk_rtw": t_sk_rtw, "first": fits[0],
                  "second": fits[1]}))
"""


LONG_SEARCH = """
import json, sys, time
from aeon.datasets import load_classification
from joblib import parallel_config
from sklearn.model_selection import GridSearchCV
from sk_rtw import DBA, RTW, RTWNearestCentroid
X, y = load_classification(sys.argv[2], split="train", extract_path=sys.argv[3])
X = X[:, 0, :]
grid = [{"method": [RTW()], "method__hidden_size": [16, 64],
         "method__learning_rate": [0.01, 0.003]}, {"method": [DBA()]}]
t = time.perf_counter()
with parallel_config(backend=sys.argv[4]):
    GridSearchCV(RTWNearestCentroid(random_state=0), grid, cv=3,
                 n_jobs=int(sys.argv[1])).fit(X, y)
print(json.dumps(time.perf_counter() - t))
"""


def fresh(code: str, *args: str) -> dict:
    """Run ``code`` in a new interpreter; its last printed line, as JSON."""
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True,
                          check=False)  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"a probe failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def median(values) -> float:
    return statistics.median(values)


def probe_align(repeat: int) -> str:
    runs = [fresh(ALIGN) for _ in range(repeat)]
    lines = [
        "| series | import sk_rtw (s) | first align (s) | second, third (median, s) | "
        "first / later |",
        "| --- | --- | --- | --- | --- |",
    ]
    for T in ("50", "1000"):
        first = median([r[T][0] for r in runs])
        later = median([median(r[T][1:]) for r in runs])
        lines.append(f"| 8 x {T} quaternions | {median([r['import'] for r in runs]):.2f} | "
                     f"{first:.2f} | {later:.2f} | {first / later:.2f}x |")  # fmt: skip
    return "\n".join(lines)


#: (n_jobs, joblib backend, label) of the search probes.
SEARCHES = (("1", "loky", "n_jobs=1"), ("2", "loky", "n_jobs=2, processes (joblib's default)"),
            ("2", "threading", "n_jobs=2, threads"))  # fmt: skip


def probe_search(repeat: int) -> str:
    lines = [
        "| GridSearchCV, 3 candidates x 3 folds | first search (s) | second search (s) |",
        "| --- | --- | --- |",
    ]
    for n_jobs, backend, label in SEARCHES:
        runs = [fresh(SEARCH, n_jobs, backend) for _ in range(repeat)]
        lines.append(f"| {label} | {median([r[0] for r in runs]):.2f} | "
                     f"{median([r[1] for r in runs]):.2f} |")  # fmt: skip
    return "\n".join(lines)


def probe_worker(repeat: int) -> str:
    runs = [fresh(WORKER) for _ in range(repeat)]
    cells = [median([r[key] for r in runs]) for key in ("sklearn", "sk_rtw", "first", "second")]
    return (
        "| import sklearn.model_selection | then import sk_rtw | first fit | second fit |\n"
        "| --- | --- | --- | --- |\n| " + " | ".join(f"{c:.2f} s" for c in cells) + " |"
    )


def probe_long_search(repeat: int, dataset: str, data_dir: str) -> str:
    header = f"| GridSearchCV on {dataset}, 5 candidates x 3 folds | search (s) |"
    lines = [header, "| --- | --- |"]
    for n_jobs, backend, label in SEARCHES:
        runs = [fresh(LONG_SEARCH, n_jobs, dataset, data_dir, backend) for _ in range(repeat)]
        lines.append(f"| {label} | {median(runs):.2f} |")
    return "\n".join(lines)


PROBES = {"align": probe_align, "search": probe_search, "worker": probe_worker,
          "long-search": probe_long_search}  # fmt: skip


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--probes", nargs="+", choices=list(PROBES), default=list(PROBES))
    parser.add_argument("--repeat", type=positive_int, default=3,
                        help="fresh processes per probe (median reported)")  # fmt: skip
    parser.add_argument("--data-dir", default="../shared/ucr",
                        help="archive in aeon's local layout, for long-search")  # fmt: skip
    parser.add_argument("--dataset", default="Plane", help="dataset of long-search")
    args = parser.parse_args(argv)
    print(f"# First calls\n\nMachine: {machine()}\n")
    for name in args.probes:
        extra = (args.dataset, str(Path(args.data_dir).resolve())) if name == "long-search" else ()
        print(f"## {name}\n\n{PROBES[name](args.repeat, *extra)}\n", flush=True)


if __name__ == "__main__":
    main()
