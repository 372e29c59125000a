"""The UCR benchmark on a dask cluster: ship this code, check the rest, fail fast.

A scheduler and workers started the usual way (``dask scheduler``, ``dask worker
ADDRESS``) need sk_rtw and aeon installed in their environment, nothing else: the
benchmark's own code (the ``benchmarks`` package of this checkout, which is not
installed anywhere) is uploaded to the scheduler and every worker, so that the task
graph unpickles there. Before any dataset is sent, every node reports which of the
modules the benchmark imports it can import and its sk_rtw version; anything missing
stops the run within seconds, naming the node and the module.
"""

from __future__ import annotations

import importlib
import sys
import tempfile
import zipfile
from pathlib import Path

#: What the scheduler (to unpickle the task graph) and the workers must import.
REQUIRED = ("numpy", "scipy", "sklearn", "torch", "numba", "joblib", "sk_rtw", "aeon")
#: Seconds to reach a scheduler before giving up.
CONNECT_TIMEOUT = 10

PACKAGE = Path(__file__).resolve().parents[1]  # benchmarks/


def environment() -> dict[str, str | None]:
    """The version of every required module on this node (None: cannot be imported)."""
    found: dict[str, str | None] = {}
    for name in REQUIRED:
        try:
            found[name] = str(getattr(importlib.import_module(name), "__version__", "?"))
        except Exception:  # a broken install counts as missing
            found[name] = None
    return found


def package_zip(folder: Path) -> Path:
    """The ``benchmarks`` package (its ``.py`` files) as a zip that dask can upload."""
    path = folder / "benchmarks.zip"
    with zipfile.ZipFile(path, "w") as archive:
        for source in sorted(PACKAGE.rglob("*.py")):
            archive.write(source, Path("benchmarks") / source.relative_to(PACKAGE))
    return path


def problems(reports: dict[str, dict[str, str | None]], here: dict[str, str | None]) -> list[str]:
    """What keeps the nodes of ``reports`` from running the benchmark of this process."""
    out = []
    for node, found in reports.items():
        missing = [name for name, version in found.items() if version is None]
        if missing:
            out.append(f"{node} cannot import {', '.join(missing)}")
        elif found["sk_rtw"] != here["sk_rtw"]:
            out.append(f"{node} has sk_rtw {found['sk_rtw']}, this checkout {here['sk_rtw']}")
    return out


def connect(scheduler: str | None, jobs: int):
    """A dask client that can run the benchmark: to ``scheduler`` (or a local cluster of
    ``jobs`` processes), this code uploaded, every node checked. ``SystemExit`` names
    what is missing."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            raise SystemExit(
                f"error: no dask scheduler answered at {scheduler} within "
                f"{CONNECT_TIMEOUT} s ({exc})"
            ) from None
    else:
        client = Client(LocalCluster(n_workers=max(jobs, 1), threads_per_worker=1))
    try:
        try:  # workers started a moment ago may still be registering
            client.wait_for_workers(1, timeout=CONNECT_TIMEOUT)
        except TimeoutError:
            raise SystemExit(
                f"error: the dask scheduler at {scheduler} has no worker (none registered "
                f"within {CONNECT_TIMEOUT} s)"
            ) from None
        with tempfile.TemporaryDirectory() as folder:
            client.upload_file(str(package_zip(Path(folder))))  # onto their sys.path
        workers = client.run(environment)
        reports = {"the scheduler": client.run_on_scheduler(environment)}
        reports.update({f"worker {address}": found for address, found in workers.items()})
        found = problems(reports, environment())
        if found:
            raise SystemExit(
                "error: the dask cluster cannot run the benchmark:\n  - "
                + "\n  - ".join(found)
                + "\ninstall sk_rtw with its aeon extra (pip install 'sk-rtw[aeon]', the "
                "version of this checkout) in the environment of the scheduler and of "
                "every worker; the benchmark's own code is sent by the script"
            )
    except BaseException:
        client.close()
        raise
    print(f"dask: {len(workers)} worker(s) ready", file=sys.stderr)
    return client
