# SPDX-License-Identifier: Apache-2.0
"""Settle: vibration-free point-to-point moves (planning, sampling, simulation).

Every function takes the move as keywords, the `settle` CLI's options without their dashes
(profile, distance, time, vmax, amax, jmax, omega, zeta, gammas, y, shaper, vtol, robust):

    >>> import settle
    >>> settle.plan(profile="scurve", distance=0.05, time=0.6, omega=22.0)["duration"]
    0.6

A bad value raises ValueError('<keyword>: <reason>'); an unknown keyword raises TypeError.
The typed signatures are in this package's stub (__init__.pyi); help(settle.plan) shows each
function's documentation. __version__ is the Settle release, as `settle --version` prints it.
"""
from ._settle import PROFILES, __version__, plan, sample, simulate

__all__ = ["PROFILES", "__version__", "plan", "sample", "simulate"]
