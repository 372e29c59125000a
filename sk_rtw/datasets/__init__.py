"""Data generators and loaders that need no network."""

from ._warped import WARP_FAMILIES, WarpedSignals, make_warped_signals

__all__ = ["WARP_FAMILIES", "WarpedSignals", "make_warped_signals"]
