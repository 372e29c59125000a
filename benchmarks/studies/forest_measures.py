"""The proximity forest's measure family: each variant of the draw, on the halves.

Usage::

    python benchmarks/studies/forest_measures.py --data-dir ../shared/ucr --halves A \
        --seeds 0 1 2 --variants default exponents-1-2 --out results/forest_measures.jsonl

For every dataset, seed and variant, the elastic forest
(:class:`sk_rtw.RTWProximityForest(random_state=seed, n_jobs=1)` with one
:class:`sk_rtw.ElasticSplitter`, no shapelet candidates) is fitted on one thread with its
measure family changed as the variant says,
and its test accuracy, fit and prediction seconds are kept (JSON lines, appended as each
dataset finishes; a rerun skips what is there). The mean accuracy per half and seed is
printed. Variants:

* ``default``: the elastic splitter as shipped (point-cost exponents 1/2, 1 and 2);
* ``exponents-1-2``: the geodesic distance or its square only (the issue's first draft,
  without Proximity Forest 2.0's exponent 1/2).

Each variant is a recipe of the elastic splitter (:class:`sk_rtw.ElasticSplitter`),
passed as the forest's ``splitters``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from benchmarks.studies._halves_cli import run_variants
from sk_rtw import ElasticSplitter, RTWProximityForest

VARIANTS = {"default": ElasticSplitter(), "exponents-1-2": ElasticSplitter(exponents=(1.0, 2.0))}


def main() -> None:
    run_variants(__doc__.splitlines()[0], VARIANTS, lambda variant, seed: RTWProximityForest(
        splitters=[VARIANTS[variant]], random_state=seed, n_jobs=1))  # fmt: skip


if __name__ == "__main__":
    main()
