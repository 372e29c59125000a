"""Shared pieces of the paper experiments: running a method, scoring, Markdown tables."""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from sk_rtw import align, metrics
from sk_rtw.align import ENGINE_METHODS
from sk_rtw.baselines import dba_average, mmddtw_align, pdtw_average, qdtw_align

from .._shared import check_writable, existing_directory, method_object, non_negative_int

LABELS = {
    "rtw": "RTW",
    "rtw-paper": "RTW (paper)",
    "rtw-class-means": "RTW (class-means)",
    "ttw-paper": "TTW (paper)",
    "ntw-paper": "NTW (paper)",
    "ttw": "TTW",
    "ntw": "NTW",
    "mmddtw": "MMDDTW",
    "mmddtw_c": "MMDDTW_C",
    "pdtw": "p-DTW",
    "qdtw": "QDTW",
    "dba": "DBA",
    "unaligned": "unaligned",
    "interpolation": "interpolation",
}


#: Extra keyword arguments of ``sk_rtw.align`` for TTW, NTW and RTW (``--options``).
ENGINE_OPTIONS: dict = {}


def paper_parser(
    doc: str, *, data: bool = True, engine: bool = True, epilog: str | None = None
) -> argparse.ArgumentParser:
    """The options every paper experiment shares (data, epochs, seed, output; with
    ``engine`` the device and the engine settings); each script adds its own."""
    parser = argparse.ArgumentParser(
        description=doc.splitlines()[0],
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    if data:
        parser.add_argument(
            "--data-dir",
            type=existing_directory,
            help="shared data folder (default: $SK_RTW_DATA_DIR, else ../shared/data)",
        )
    parser.add_argument("--epochs", type=non_negative_int, default=256,
                        help="most epochs of TTW, NTW and RTW (default 256)")  # fmt: skip
    parser.add_argument("--seed", type=non_negative_int, default=0)
    if engine:
        parser.add_argument("--device", default="cpu", help="torch device of TTW, NTW, RTW")
        add_engine_options(parser)
    parser.add_argument("--markdown", help="also write the tables to this Markdown file")
    return parser


def parse_paper_args(parser: argparse.ArgumentParser, argv=None) -> argparse.Namespace:
    """Parse, then check what argparse cannot (settings, device, the output file) before
    any work."""
    from sk_rtw.align import check_device

    args = parser.parse_args(argv)
    if hasattr(args, "options"):
        apply_engine_options(args)
        try:
            check_device(args.device)
        except ValueError as exc:
            parser.error(str(exc))
    if args.markdown:
        check_writable(args.markdown)
    return args


def add_engine_options(parser: argparse.ArgumentParser) -> None:
    """The ``--options`` argument: engine options as JSON, applied by :func:`run_method`."""
    parser.add_argument(
        "--options",
        type=json.loads,
        default={},
        help="extra sk_rtw.align settings for TTW/NTW/RTW as JSON, each applied to the "
        'methods that have it, e.g. \'{"warp_knots": null, "tangent_refinements": 2}\' '
        "(network at every output time, refined tangent points)",
    )


def apply_engine_options(args: argparse.Namespace) -> None:
    """Check ``--options`` against the knob table (names and values) before any work."""
    from sk_rtw.align import KNOBS

    if not isinstance(args.options, dict):
        raise SystemExit(f"error: --options must be a JSON object, got {args.options!r}")
    for name, value in args.options.items():
        if name not in KNOBS:
            raise SystemExit(f"error: --options: {name!r} is no setting (known: {sorted(KNOBS)})")
        try:
            KNOBS[name].with_auto().check(value)
        except ValueError as exc:
            raise SystemExit(f"error: --options: {exc}") from None
    ENGINE_OPTIONS.clear()
    ENGINE_OPTIONS.update(args.options)


@dataclass
class Outcome:
    """What every method returns: a mean, the aligned series, warps in [0, 1], seconds."""

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    seconds: float


def run_method(
    method: str,
    X,
    manifold,
    *,
    epochs: int = 256,
    output_length: int | None = None,
    seed: int = 0,
    device: str = "cpu",
) -> Outcome:
    """Run one method of the paper's tables (or DBA) on the series ``X``.

    ``"rtw"``, ``"ttw"``, ``"ntw"`` run the engine with the product defaults, ``"rtw-paper"``
    (and ``"ttw-paper"``, ``"ntw-paper"``) with ``preset="paper"``, ``"rtw-class-means"``
    with the estimators' preset (density-weighted mean on the reference's time axis).
    """
    start = time.perf_counter()
    engine_method, _, variant = method.partition("-")
    if engine_method in ENGINE_METHODS and variant in ("", "paper", "class-means"):
        lengths = {} if output_length is None else {"output_length": output_length}
        settings = method_object(engine_method, **ENGINE_OPTIONS, n_epochs=epochs, **lengths)
        r = align(
            X,
            manifold=manifold,
            method=settings,
            preset=variant or "alignment",
            random_state=seed,
            device=device,
        )
    elif method == "mmddtw":
        r = mmddtw_align(X, manifold)
    elif method == "mmddtw_c":
        r = mmddtw_align(X, manifold, metric="cholesky")
    elif method == "qdtw":
        r = qdtw_align(X)
    elif method == "pdtw":
        r = pdtw_average(X, manifold)
    elif method == "dba":
        r = dba_average(X, manifold)
    else:
        raise ValueError(f"unknown method {method!r}")
    return Outcome(r.mean, r.aligned, r.warps, time.perf_counter() - start)


def unaligned(X, manifold, length: int | None = None) -> Outcome:
    """Naive interpolation: every series resampled to one length, then averaged pointwise.

    Resampling picks the nearest sample at evenly spaced relative positions; the mean is
    the Fréchet mean across series at every step.
    """
    series = [np.asarray(s) for s in X]
    length = length or max(len(s) for s in series)
    grid = np.linspace(0.0, 1.0, length)
    aligned = np.stack([s[np.round(grid * (len(s) - 1)).astype(int)] for s in series])
    mean = manifold.mean(aligned)
    return Outcome(mean, aligned, np.tile(grid, (len(series), 1)), 0.0)


def score(outcome: Outcome, X, manifold, original=None) -> dict[str, float]:
    """Barycenter loss, alignment quality (and restoration accuracy given ``original``)."""
    values = {}
    if original is not None:
        values["RA"] = metrics.restoration_accuracy(outcome.aligned, original, manifold)
    values["BL"] = metrics.barycenter_loss(X, outcome.mean, manifold)
    values["AQ"] = metrics.alignment_quality(outcome.aligned, outcome.mean, manifold)
    values["seconds"] = outcome.seconds
    return values


def evaluate(
    X, manifold, methods, *, epochs: int, seed: int, device: str
) -> dict[str, dict[str, float]]:
    """Scores of naive interpolation ("unaligned") and of every method on the series X."""
    results = {"unaligned": score(unaligned(X, manifold), X, manifold)}
    for method in methods:
        outcome = run_method(method, X, manifold, epochs=epochs, seed=seed, device=device)
        results[method] = score(outcome, X, manifold)
    return results


def machine() -> str:
    return (
        f"{platform.machine()}, {os.cpu_count()} cores, fits on one thread (n_jobs=None), "
        f"torch {torch.__version__}, Python {platform.python_version()}"
    )


def command_line() -> str:
    return "python " + shlex.join([Path(sys.argv[0]).as_posix(), *sys.argv[1:]])


def format_cell(values: Sequence[float], best: bool = False) -> str:
    values = np.asarray(values, dtype=float)
    text = f"{values.mean():.4g}"
    if len(values) > 1:
        text += f" ± {values.std():.2g}"
    return f"**{text}**" if best else text


def markdown_table(
    results: dict[str, list[dict[str, float]]],
    columns: Sequence[str],
    paper: dict[str, Sequence[float]] | None = None,
) -> str:
    """One row per method: mean ± std over runs, best (lowest mean) in bold, paper values."""
    means = {
        c: {m: np.mean([r[c] for r in rows]) for m, rows in results.items() if rows}
        for c in columns
    }
    best = {
        c: min((v, m) for m, v in means[c].items() if m not in ("unaligned", "interpolation"))[1]
        for c in columns
        if c != "seconds" and len(means[c]) > 1
    }
    header = ["method", *columns] + (["paper"] if paper else [])
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for method, rows in results.items():
        if not rows:
            continue
        cells = [LABELS.get(method, method)]
        cells += [format_cell([r[c] for r in rows], best.get(c) == method) for c in columns]
        if paper:
            cells.append(" / ".join(f"{v:g}" for v in paper.get(method, ())) or "")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def write_markdown(
    path: str | None, title: str, intro: str, sections: dict[str, str], quiet: bool = False
) -> None:
    """Print the tables (unless ``quiet``) and, with ``path``, write them as a Markdown page."""
    body = [f"# {title}", "", intro.strip(), "", f"Command: `{command_line()}`", ""]
    if ENGINE_OPTIONS:
        body += [f"Engine options for TTW/NTW/RTW: `{json.dumps(ENGINE_OPTIONS)}`.", ""]
    body += [f"Machine: {machine()}.", ""]
    for heading, text in sections.items():
        body += [f"## {heading}", "", text.strip(), ""]
    page = "\n".join(body)
    if not quiet:
        print(page, flush=True)
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(page)
        print(f"written to {path}", file=sys.stderr)
