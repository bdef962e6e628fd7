# SPDX-License-Identifier: Apache-2.0
# Typed signatures of the settle package (PEP 561: py.typed ships beside this stub). The move's
# keywords are the `settle` CLI's options without their dashes, each with the CLI's unit and range
# (`settle plan --help`); a keyword left out is the CLI's option left out.
from typing import Any, Iterable, Literal, Sequence, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str
PROFILES: tuple[str, ...]

Number = Union[int, float]
Modes = Union[Number, Sequence[Number]]
FloatArray = npt.NDArray[np.float64]

class Samples(TypedDict):
    t: FloatArray
    position: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray

def plan(
    *,
    profile: str,
    distance: Number,
    time: Number | None = ...,
    vmax: Number | None = ...,
    amax: Number | None = ...,
    jmax: Number | None = ...,
    omega: Modes | None = ...,
    zeta: Modes = ...,
    gammas: Iterable[Number] | None = ...,
    y: Iterable[Number] | None = ...,
    shaper: str | None = ...,
    vtol: Number = ...,
    robust: Number = ...,
) -> dict[str, Any]:
    """The planned move as `settle plan --json` prints it (status, profile, distance, duration,
    profile_duration, params, peaks, shaper.impulses); an infinite peak is math.inf."""

def sample(
    *,
    dt: Number,
    profile: str,
    distance: Number,
    time: Number | None = ...,
    vmax: Number | None = ...,
    amax: Number | None = ...,
    jmax: Number | None = ...,
    omega: Modes | None = ...,
    zeta: Modes = ...,
    gammas: Iterable[Number] | None = ...,
    y: Iterable[Number] | None = ...,
    shaper: str | None = ...,
    vtol: Number = ...,
    robust: Number = ...,
) -> Samples:
    """The move at t = 0, dt, 2 dt, ... (s) and at its end, as `settle sample --dt` prints it."""

def simulate(
    *,
    plant: Literal["sdof", "beam", "belt"] | Sequence[Sequence[Number]],
    dt: Number = ...,
    profile: str,
    distance: Number,
    time: Number | None = ...,
    vmax: Number | None = ...,
    amax: Number | None = ...,
    jmax: Number | None = ...,
    omega: Modes | None = ...,
    zeta: Modes = ...,
    gammas: Iterable[Number] | None = ...,
    y: Iterable[Number] | None = ...,
    shaper: str | None = ...,
    vtol: Number = ...,
    robust: Number = ...,
) -> dict[str, Any]:
    """Residual-vibration metrics of the move on a plant ('sdof', 'beam', 'belt' or a list of
    (omega, zeta[, gain]) modes): residual_amplitude, step_residual, prv_percent, peak_deflection,
    final_energy, settling_band, settling_time, move_end, distance, mode_residual and
    mode_prv_percent (numpy arrays, one entry per mode)."""
