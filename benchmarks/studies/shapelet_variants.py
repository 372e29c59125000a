"""The shapelet classifier's draw: each variant of its defaults, on the halves.

Usage::

    python benchmarks/studies/shapelet_variants.py --data-dir ../shared/ucr --halves A B \
        --seeds 0 1 2 --variants default normalised-0.8 raw rdst \
        --out results/shapelet_variants.jsonl

For every dataset, seed and variant, ``GeodesicShapeletClassifier(random_state=seed,
n_jobs=1)`` is fitted on one thread with the parameters the variant names, and its test
accuracy and fit and prediction CPU seconds are kept (JSON lines, appended as each
dataset finishes; a rerun skips what is there). The mean accuracy per half and seed is
printed: a variant becomes the default only if it wins where defaults are chosen
(halves A and C1) and is confirmed on B and C2. Variants:

* ``default``: as shipped (half the shapelets normalised; from the series and their
  velocity, shapelet by shapelet);
* ``normalised-0.8``: ``normalised_fraction=0.8``, aeon's RDST default;
* ``raw``: ``representation="raw"``, shapelets from the series only, as RDST draws them;
* ``rdst``: both, RDST's draw (but for its alpha-similarity mask).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from benchmarks.studies._halves_cli import run_variants
from sk_rtw import GeodesicShapeletClassifier

VARIANTS = {
    "default": {},
    "normalised-0.8": {"normalised_fraction": 0.8},
    "raw": {"representation": "raw"},
    "rdst": {"representation": "raw", "normalised_fraction": 0.8},
}


def main() -> None:
    run_variants(__doc__.splitlines()[0], VARIANTS, lambda variant, seed: (
        GeodesicShapeletClassifier(**VARIANTS[variant], random_state=seed, n_jobs=1)),
        clock=time.process_time)  # fmt: skip


if __name__ == "__main__":
    main()
