"""Speed and memory of sk_rtw's fits next to aeon's DBA, on the same machine in one run.

Usage::

    python benchmarks/align_speed.py                    # every section, about 6 min on 2 cores
    python benchmarks/align_speed.py --sections fits busy
    python benchmarks/align_speed.py --sections estimators --data-dir ../shared/ucr
    python benchmarks/align_speed.py --sections poses --shared-data ../shared/data
    python benchmarks/align_speed.py --device cuda --sections fits epochs   # on a GPU
    python benchmarks/align_speed.py --device cuda --sections fits epochs --cuda-graph

Sections (each number is the median of ``--repeats`` runs after a warm-up run; the
machine's noise is large, so compare the printed ratios, not absolute seconds):

``fits``
    one fit with the defaults of ``sk_rtw.align`` on N = 30 Euclidean warped signals of
    length T = 100 (RTW, TTW, NTW) and aeon's DBA (``elastic_barycenter_average``, DTW)
    on the same signals, each in a fresh process on 1 and on 2 threads (aeon on numba's
    default threading layer); then S^1 (N = 30, T = 100) and one S^1 class of 2,000
    series with its peak resident memory.
``epochs``
    milliseconds per epoch against N (4, 30, 120; 2,000 on a GPU), Euclidean and S^1,
    ``(fit(E epochs) - fit(0 epochs)) / E`` with early stopping switched off.
``estimators``
    ``RTWNearestCentroid`` fit time of RTW and of ``method="dba"`` on every UCR dataset of
    ``--data-dir`` (full training sets): the total ratio and the largest per dataset.
``poses``
    RTW on the real pose demonstrations at full resolution (``--shared-data``, R^3 x S^3):
    carrot grating (12 demonstrations of 2,322-3,371 samples) and circular wiping (4 of
    1,096-1,457), seconds and peak resident memory, each in a fresh process.
``budget``
    where the default fit of N = 30 Euclidean series of T = 100 spends its time, one
    thread: the setup (``n_epochs=0``: checks, DTW start, final mean), the epochs of the
    width-512 network and of a width-8 one (``(fit(32 epochs) - setup) / 32``, early
    stopping off), and what 3x aeon's DBA would leave per epoch for everything but the
    network at the epochs the default runs.
``busy``
    a default fit while another process keeps one core busy with numerical work, against
    the same fit on a quiet machine (and with torch's default threads, the old behaviour);
    aeon's DBA in a fresh process, after ``import sk_rtw``, and after an sk_rtw fit.

Only public APIs are used, so the script also times older versions (``PYTHONPATH=<old
checkout>``); keywords an older version lacks are left out.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SECTIONS = ("fits", "epochs", "budget", "estimators", "poses", "busy")

#: Runs in every probe process: timing helpers and the warped signals.
PRELUDE = """
import inspect, json, os, resource, statistics, sys, time
import numpy as np

def timed(fn, repeats):
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)

def peak_mib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

def signals(space, n, length=100):
    from sk_rtw.datasets import make_warped_signals
    return np.asarray(make_warped_signals(space, n, length, random_state=0).signals)

def fit(X, space, method="rtw", threads=1, device="cpu", **options):
    import torch
    from sk_rtw import align
    accepted = inspect.signature(align).parameters
    if "n_jobs" in accepted:
        options["n_jobs"] = threads
    else:  # older versions: torch's own thread count
        torch.set_num_threads(threads)
    every = any(p.kind is p.VAR_KEYWORD for p in accepted.values())  # align(X, **settings)
    options = {k: v for k, v in options.items()
               if every or k in accepted or k not in ("n_iter_no_change",)}
    return align(X, manifold=space, method=method, random_state=0, device=device, **options)
"""


def checkout() -> Path:
    """The checkout whose sk_rtw this process imports: the probes run there (an older
    version timed with ``PYTHONPATH=<old checkout>`` is timed in every probe too)."""
    import sk_rtw

    return Path(sk_rtw.__file__).resolve().parents[1]


def probe(code: str, threads: int | None = None, env: dict | None = None,
          replace: bool = False) -> dict:  # fmt: skip
    """Run ``code`` (after :data:`PRELUDE`) in a fresh process; it prints one JSON line.

    ``env`` adds to this process's environment, or replaces it with ``replace=True``."""
    environment = dict(env or {}) if replace else {**os.environ, **(env or {})}
    if threads is not None:
        environment.update(NUMBA_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    out = subprocess.run(
        [sys.executable, "-c", PRELUDE + textwrap.dedent(code)],
        capture_output=True,
        text=True,
        env=environment,
        cwd=checkout(),
    )
    if out.returncode != 0:
        raise RuntimeError(f"probe failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


AEON_DBA = """
from aeon.clustering.averaging import elastic_barycenter_average
# random walks, made without sk_rtw: the "fresh process" row must not import it
X = np.cumsum(np.random.default_rng(0).standard_normal((30, 1, 100)), axis=2)
{before}
seconds = timed(lambda: elastic_barycenter_average(X, distance="dtw", random_state=0), {repeats})
print(json.dumps({{"seconds": seconds}}))
"""


def aeon_dba(threads: int, repeats: int, before: str = "") -> float:
    """aeon's DBA in a fresh process on numba's own choice of threading layer (the
    variable is cleared: setting it would also stop an older sk_rtw from changing it)."""
    code = AEON_DBA.format(before=before, repeats=repeats)
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_THREADING_LAYER"}
    return probe(code, threads, env=environment, replace=True)["seconds"]


#: Options added to every engine fit (``--cuda-graph``).
EXTRA_OPTIONS: dict = {}


def engine_fit(space, n, method, threads, repeats, device="cpu", **options) -> dict:
    """One configuration in a fresh process; ``seconds`` is NaN where this version lacks an
    option (older versions have no ``preset="class-means"``)."""
    options = {**EXTRA_OPTIONS, **options}
    code = f"""
    X = signals({space!r}, {n})
    try:
        fit(X, {space!r}, {method!r}, {threads}, {device!r}, **{{**{options!r}, "n_epochs": 1}})
    except (TypeError, ValueError):
        print(json.dumps({{"seconds": float("nan"), "epochs": -1, "peak_mib": peak_mib()}}))
        sys.exit()
    options = {options!r}
    result = {{}}
    result["seconds"] = timed(lambda: fit(X, {space!r}, {method!r}, {threads}, {device!r},
                                          **options), {repeats})
    last = fit(X, {space!r}, {method!r}, {threads}, {device!r}, **options)
    result["epochs"] = int(getattr(last, "n_iter", len(last.loss_history)))
    result["peak_mib"] = peak_mib()
    print(json.dumps(result))
    """
    return probe(code, threads)


def machine(device: str) -> str:
    import torch

    name = platform.processor() or platform.machine()
    if device.startswith("cuda") and torch.cuda.is_available():
        name += f", GPU {torch.cuda.get_device_name(0)}"
    import sk_rtw

    return (
        f"{name}, {os.cpu_count()} cores, Python {platform.python_version()}, torch "
        f"{torch.__version__}, sk_rtw {sk_rtw.__version__} from {Path(sk_rtw.__file__).parent}"
    )


# ------------------------------------------------------------------- sections
def section_fits(args) -> None:
    print("\n## 1. One fit, defaults, N = 30 Euclidean series, T = 100 (fresh processes)\n")
    print(
        "RTW with `align`'s defaults, and with the estimators' (`preset=\"class-means\"`, "
        "width-64 network, quicker stop).\n"
    )
    print(
        "| threads | aeon DBA alone (s) | RTW (s) | RTW / DBA | RTW class-means (s) | / DBA "
        "| TTW (s) | NTW (s) | RTW epochs |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for threads in (1, 2):
        dba = aeon_dba(threads, args.repeats)
        rtw = engine_fit("euclidean", 30, "rtw", threads, args.repeats, args.device)
        means = engine_fit("euclidean", 30, "rtw", threads, args.repeats, args.device,
                           preset="class-means")  # fmt: skip
        ttw = engine_fit("euclidean", 30, "ttw", threads, args.repeats, args.device)
        ntw = engine_fit("euclidean", 30, "ntw", threads, args.repeats, args.device)
        print(
            f"| {threads} | {dba:.3f} | {rtw['seconds']:.3f} | **{rtw['seconds'] / dba:.2f}** "
            f"| {means['seconds']:.3f} | **{means['seconds'] / dba:.2f}** "
            f"| {ttw['seconds']:.3f} | {ntw['seconds']:.3f} | {rtw['epochs']} |",
            flush=True,
        )
    print("\n## 2. S^1 fits (defaults, 1 thread unless stated)\n")
    s1 = engine_fit("sphere", 30, "rtw", 1, args.repeats, args.device)
    s1_fast = engine_fit("sphere", 30, "rtw", 1, args.repeats, args.device,
                         preset="class-means")  # fmt: skip
    print(
        f"- N = 30, T = 100: RTW {s1['seconds']:.3f} s per fit ({s1['epochs']} epochs); "
        f"preset='class-means' {s1_fast['seconds']:.3f} s ({s1_fast['epochs']} epochs)"
    )
    if args.skip_large:
        return
    for threads in (1, 2):
        big = engine_fit("sphere", 2000, "rtw", threads, 1, args.device)
        print(
            f"- one class of 2,000 series, T = 100, Z = 400, {threads} thread(s): RTW "
            f"{big['seconds']:.1f} s per fit ({big['epochs']} epochs), peak resident memory "
            f"{big['peak_mib']:.0f} MiB",
            flush=True,
        )


def section_epochs(args) -> None:
    sizes = (4, 30, 120, 2000) if args.device.startswith("cuda") else (4, 30, 120)
    print("\n## 3. Milliseconds per epoch, T = 100, default Z = min(N, 4) T, 1 thread\n")
    print("| space | N | rtw | ttw | ntw |")
    print("| --- | --- | --- | --- | --- |")
    for space in ("euclidean", "sphere"):
        for n in sizes:
            epochs = 16 if n >= 1000 else 32
            row = []
            for method in ("rtw", "ttw", "ntw"):
                full = engine_fit(space, n, method, 1, args.repeats, args.device,
                                  n_epochs=epochs, n_iter_no_change=None)  # fmt: skip
                setup = engine_fit(space, n, method, 1, args.repeats, args.device, n_epochs=0)
                row.append(max(full["seconds"] - setup["seconds"], 0.0) / epochs * 1e3)
            name = "S^1" if space == "sphere" else "R^1"
            print(f"| {name} | {n} | " + " | ".join(f"{v:.2f}" for v in row) + " |", flush=True)


def section_budget(args) -> None:
    print("\n## Where the default N = 30, T = 100 fit spends its time (1 thread)\n")
    dba = aeon_dba(1, args.repeats)
    default = engine_fit("euclidean", 30, "rtw", 1, args.repeats, args.device)
    epochs = default["epochs"]
    per_epoch = {}
    setup = {}
    for width in (512, 8):
        options = {"hidden_size": width}
        setup[width] = engine_fit("euclidean", 30, "rtw", 1, args.repeats, args.device,
                                  n_epochs=0, **options)["seconds"]  # fmt: skip
        full = engine_fit("euclidean", 30, "rtw", 1, args.repeats, args.device, n_epochs=32,
                          n_iter_no_change=None, start_patience=None, **options)  # fmt: skip
        per_epoch[width] = (full["seconds"] - setup[width]) / 32
    network = per_epoch[512] - per_epoch[8]
    rest = (3 * dba - setup[512]) / epochs - network
    print(
        "| aeon DBA (s) | RTW default (s) | epochs | setup (s) | ms per epoch, width 512 "
        "| width 8 | the network's share | ms per epoch left for the rest at 3x DBA |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    print(
        f"| {dba:.3f} | {default['seconds']:.3f} ({default['seconds'] / dba:.2f}x) | {epochs} "
        f"| {setup[512]:.3f} | {per_epoch[512] * 1e3:.2f} | {per_epoch[8] * 1e3:.2f} "
        f"| {network * 1e3:.2f} | **{rest * 1e3:.2f}** (against {per_epoch[8] * 1e3:.2f}) |",
        flush=True,
    )


ESTIMATORS = """
import warnings
import torch
from benchmarks.ucr._data import available_datasets, load_split
from sk_rtw import RTWNearestCentroid
torch.set_num_threads(1)
names = [n for n in available_datasets({data_dir!r})
         if os.path.isdir(os.path.join({data_dir!r}, n))]
rng = np.random.default_rng(0)
warm = rng.standard_normal((8, 30)).cumsum(1)
for method in ("rtw", "dba"):  # warm-up: numba's cached kernels, torch's first calls
    RTWNearestCentroid(method=method, random_state=0).fit(warm, [0] * 4 + [1] * 4)
rows = []
for name in names:
    train = load_split(name, "train", {data_dir!r})
    times = {{}}
    for method in ("rtw", "dba"):
        start = time.perf_counter()
        RTWNearestCentroid(method=method, random_state=0).fit(train.X, train.y)
        times[method] = time.perf_counter() - start
    rows.append((name, times["rtw"], times["dba"]))
print(json.dumps(rows))
"""


def section_estimators(args) -> None:
    if not args.data_dir:
        print("\n## 4. Estimators: skipped (no --data-dir)")
        return
    rows = probe(ESTIMATORS.format(data_dir=str(Path(args.data_dir).resolve())), threads=1)
    rtw = sum(r[1] for r in rows)
    dba = sum(r[2] for r in rows)
    ratios = sorted(((r[1] / r[2], r[0], r[1], r[2]) for r in rows), reverse=True)
    print(f"\n## 4. Estimators: RTWNearestCentroid fit, {len(rows)} UCR datasets, 1 thread\n")
    print(f"- total fit time: RTW {rtw:.1f} s, DBA {dba:.1f} s, **ratio {rtw / dba:.2f}**")
    above = [f"{name} {ratio:.1f}x ({r:.3f} s vs {d:.3f} s)" for ratio, name, r, d in ratios
             if ratio > 5]  # fmt: skip
    print(f"- largest per-dataset ratio: {ratios[0][1]} {ratios[0][0]:.1f}x")
    print(f"- datasets above 5x: {len(above)}" + (": " + "; ".join(above) if above else ""))
    print("\n| dataset | RTW (s) | DBA (s) | ratio |\n| --- | --- | --- | --- |")
    for ratio, name, r, d in sorted(ratios, key=lambda row: row[1]):
        print(f"| {name} | {r:.3f} | {d:.3f} | {ratio:.1f} |")


POSES = """
import torch
sys.path.insert(0, ".")
from benchmarks.paper._data import data_dir, icsc_carrot_grating, icsc_wiping
from sk_rtw.manifolds import Euclidean, Product, Quaternion
series = {{"grating": icsc_carrot_grating, "wiping": icsc_wiping}}[{task!r}](data_dir({root!r}))
M = Product((Euclidean(3), Quaternion()))
before = peak_mib()
start = time.perf_counter()
result = fit(series, M, "rtw", {threads}, {device!r})
seconds = time.perf_counter() - start
print(json.dumps({{"seconds": seconds, "peak_mib": peak_mib(), "before_mib": before,
                   "epochs": int(getattr(result, "n_iter", 256)), "Z": len(result.mean),
                   "lengths": [len(s) for s in series]}}))
"""


def section_poses(args) -> None:
    print("\n## 5. Poses at full resolution (R^3 x S^3, defaults, one fit each, fresh process)\n")
    print("| task | N | T | Z | threads | seconds | epochs | peak memory (MiB) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for task in ("wiping", "grating"):
        for threads in (1, 2):
            code = POSES.format(task=task, root=args.shared_data, threads=threads,
                                device=args.device)  # fmt: skip
            r = probe(code, threads)
            lengths = f"{min(r['lengths'])}-{max(r['lengths'])}"
            print(
                f"| {task} | {len(r['lengths'])} | {lengths} | {r['Z']} | {threads} | "
                f"{r['seconds']:.1f} | {r['epochs']} | {r['peak_mib']:.0f} |",
                flush=True,
            )


BUSY = """
import numba, torch
import numpy as np
torch.set_num_threads(1)
@numba.njit(cache=False)
def spin(a):
    s = 0.0
    for i in range(a.size):
        s += np.sin(a[i])
    return s
a = np.random.default_rng(0).standard_normal(200_000)
m = torch.randn(200, 200, dtype=torch.float64)
while True:  # one core of numerical work (numba, then torch), until killed
    spin(a)
    m = torch.tanh(m @ m / 200.0)
"""

BUSY_FIT = """
X = signals("euclidean", 30)
threads = {threads}
if threads == "torch-default":  # the old behaviour: torch's default thread count
    import torch
    from sk_rtw import align
    run = lambda: align(X, random_state=0)
    torch.set_num_threads(os.cpu_count())
else:
    run = lambda: fit(X, "euclidean", "rtw", threads)
print(json.dumps({{"seconds": timed(run, {repeats})}}))
"""


def section_busy(args) -> None:
    print("\n## 6. A busy machine, and sk_rtw's neighbours\n")
    rows = []
    for threads in (None, 2, "torch-default"):
        label = {None: "default (n_jobs=None)", 2: "n_jobs=2",
                 "torch-default": "caller set torch to all cores"}[threads]  # fmt: skip
        code = BUSY_FIT.format(threads=repr(threads if threads is not None else 1),
                               repeats=args.repeats)  # fmt: skip
        quiet = probe(code)["seconds"]
        load = subprocess.Popen([sys.executable, "-c", BUSY], cwd=checkout())
        try:
            time.sleep(2.0)
            busy = probe(code)["seconds"]
        finally:
            load.kill()
            load.wait()
        rows.append((label, quiet, busy))
    print("| RTW fit, N = 30, T = 100 | quiet (s) | one core busy (s) | busy / quiet |")
    print("| --- | --- | --- | --- |")
    for label, quiet, busy in rows:
        print(f"| {label} | {quiet:.3f} | {busy:.3f} | **{busy / quiet:.2f}** |")
    fresh = aeon_dba(2, args.repeats)
    imported = aeon_dba(2, args.repeats, before="import sk_rtw")
    after_fit = aeon_dba(
        2, args.repeats,
        before="import sk_rtw\nfrom sk_rtw import RTWNearestCentroid, dtw_pairwise_distance\n"
        "Y = signals('euclidean', 30)\nRTWNearestCentroid(random_state=0, n_jobs=-1).fit(Y, "
        "[0] * 15 + [1] * 15)\ndtw_pairwise_distance(Y, n_jobs=2)",
    )  # fmt: skip
    print("\n| aeon's DBA (N = 30, T = 100), numba's default layer | seconds | / fresh |")
    print("| --- | --- | --- |")
    for label, value in (("fresh process", fresh), ("after `import sk_rtw`", imported),
                         ("after sk_rtw fits and DTW on 2 threads", after_fit)):  # fmt: skip
        print(f"| {label} | {value:.3f} | **{value / fresh:.2f}** |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("Sections")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--sections", nargs="+", default=list(SECTIONS), choices=SECTIONS)
    parser.add_argument("--device", default="cpu", help="torch device, e.g. cuda")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per number")
    parser.add_argument("--skip-large", action="store_true", help="skip the 2,000-series class")
    parser.add_argument("--data-dir", help="UCR archive for the estimators section")
    parser.add_argument(
        "--shared-data", default=None, help="demonstration data (default ../shared/data)"
    )
    parser.add_argument(
        "--cuda-graph", action="store_true", help="capture epochs as CUDA graphs (GPU only)"
    )
    args = parser.parse_args(argv)
    if args.cuda_graph:
        EXTRA_OPTIONS["cuda_graph"] = True
    print(f"machine: {machine(args.device)}" + (", CUDA graphs" if args.cuda_graph else ""))
    sections = {"fits": section_fits, "epochs": section_epochs, "budget": section_budget,
                "estimators": section_estimators, "poses": section_poses,
                "busy": section_busy}  # fmt: skip
    for name in args.sections:
        sections[name](args)


if __name__ == "__main__":
    main()
