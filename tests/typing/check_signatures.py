"""Checked by mypy in CI (not run by pytest): static tools see the written signatures.

Every ``type: ignore`` below must be needed; mypy reports one that is not
(``warn_unused_ignores``), so a signature that static tools cannot see fails CI.
"""

from sk_rtw import DBA, RTW, RTWAverager, RTWKMeans, RTWNearestCentroid, TTWNearestCentroid

RTWNearestCentroid("sphere", method=RTW(hidden_size=64), n_centroids=4, dtw_window=0.1)
RTWNearestCentroid(hidden_size=64)  # type: ignore[call-arg]
TTWNearestCentroid(method=3.5)  # type: ignore[arg-type]
RTWAverager(n_centroids=None)  # type: ignore[arg-type]
RTWKMeans(3, method=DBA(max_iter=20), tol=1e-3)
RTWKMeans(n_cluster=3)  # type: ignore[call-arg]
RTW(n_components=8)  # type: ignore[call-arg]
RTW(0.5)  # type: ignore[call-arg, arg-type]
