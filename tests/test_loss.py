"""The loss: the Gaussian window weights against the literal window loss, and the
monotonicity penalty."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.align._loss import monotonicity_penalty, window_weights


# ------------------------------------------------------------------- losses
@pytest.mark.parametrize(("Z", "kappa", "rho"), [(50, 5, 5), (20, 3, 2), (7, 5, 5), (30, 0, 1)])
def test_window_weights_equal_the_literal_window_loss(Z, kappa, rho, rng):
    d = rng.uniform(size=(3, Z))
    sigma = kappa * rho / 3 + 1e-6
    literal = 0.0
    for n in range(3):
        for z in range(Z):
            g = np.array(
                [np.exp(-((k * rho) ** 2) / (2 * sigma**2)) for k in range(-kappa, kappa + 1)]
            )
            for k, gk in zip(range(-kappa, kappa + 1), g / g.sum(), strict=True):
                literal += gk * d[n, min(max(z + k * rho, 0), Z - 1)]
    literal /= 3 * Z
    c = window_weights(Z, kappa, rho).numpy()
    assert (d * c).mean() == pytest.approx(literal, rel=1e-12)
    if kappa == 0:
        np.testing.assert_allclose(c, 1.0)


def test_monotonicity_penalty():
    w = torch.tensor([[0.0, 0.3, 0.2, 0.6, 0.5, 1.0]])
    assert float(monotonicity_penalty(w)) == pytest.approx(0.2)
