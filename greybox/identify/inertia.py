"""Whether the runs can tell an inertia from a spring force.

On a sinusoidal run the acceleration is ``a = -w^2 x`` about the run's mean
position, so an inertia ``J a`` is indistinguishable from a force ``-J w^2 x``
in proportion to the displacement: the stiffness of a spring, a cable or a
device's elastic end stops. A model without such a term then fits ``J`` to
stand in for it, and the fitted "inertia" grows with the square of the
excitation frequency of the next run (the ARTS friction device's force,
measured at the device, gave an inertia of 3.7 t this way). When one such
spring law explains the acceleration of every run, the inertia is not
identifiable from them; :func:`spring_share` measures how far that holds.

The measure is taken in the band of the motion: position and acceleration
are low-passed (zero phase) at :data:`BAND_HARMONICS` times each run's
fundamental frequency (the peak of its velocity's spectrum), so that the
ripple and noise a differentiated acceleration carries far above the motion
do not hide the law. The limit is the usual one of regression diagnostics
for collinear regressors: a share of 0.8 is a variance inflation factor of
5, beyond which the two coefficients (here the inertia and a stiffness) are
not told apart by the data.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from scipy.signal import butter, sosfiltfilt

__all__ = ["AXIS_INERTIA_FACTOR", "BAND_HARMONICS", "SPRING_SHARE_LIMIT", "spring_share", "inertia_note",
           "axis_inertia_note"]

#: Factor by which an identified inertia may exceed, or fall short of, the axis file's before it is flagged: a
#: drive's commissioning and the data sheets give the inertia to some ten percent, the moved mass (workpiece,
#: fixtures) changes it by tens of percent, but not by half or twice.
AXIS_INERTIA_FACTOR = 2.0

#: Share of the acceleration's variance one spring law ``a = -c x`` may explain before an identified
#: inertia counts as a stand-in for a stiffness (0.8: a variance inflation factor of 5).
SPRING_SHARE_LIMIT = 0.8

#: The band of the motion, in multiples of a run's fundamental frequency.
BAND_HARMONICS = 5.0


def _in_band(run) -> tuple[np.ndarray, np.ndarray]:
    """Position and acceleration of a run about their means, low-passed to the band of its motion."""
    x = run.position - np.mean(run.position)
    a = run.acceleration - np.mean(run.acceleration)
    step = float(run.sample_time)
    spectrum = np.abs(np.fft.rfft(run.velocity - np.mean(run.velocity)))
    if len(run) < 64 or spectrum.size < 3 or not np.isfinite(step) or step <= 0.0:
        return x, a
    fundamental = np.fft.rfftfreq(len(run), step)[1 + int(np.argmax(spectrum[1:]))]
    cutoff = BAND_HARMONICS * fundamental
    if cutoff >= 0.4 / step:  # the motion fills the band already
        return x, a
    sos = butter(4, cutoff, fs=1.0 / step, output="sos")
    return sosfiltfilt(sos, x), sosfiltfilt(sos, a)


def spring_share(runs: Sequence) -> float:
    """Share of the acceleration's variance explained by one spring law ``a = -c (x - mean x)`` over all runs.

    Each run's position and acceleration are taken about their own means, in
    the band of its motion (see the module notes); one
    coefficient ``c`` [1/s^2] is fitted to the runs together by least squares. 1 means the
    acceleration is a displacement times a constant (sinusoidal runs of one
    frequency), 0 that no such law explains any of it, or that it points the
    other way (``c <= 0``: no spring pulls back).

    Parameters
    ----------
    runs : sequence of AxisLog
        Prepared runs: position [mm] and acceleration [mm/s^2].

    Returns
    -------
    float
        The explained share in [0, 1]; 0 for runs that do not accelerate or do not move.
    """
    bands = [_in_band(run) for run in runs]
    x = np.concatenate([x for x, _ in bands])
    a = np.concatenate([a for _, a in bands])
    xx, aa = float(x @ x), float(a @ a)
    if xx <= 0.0 or aa <= 0.0:
        return 0.0
    slope = float(a @ x) / xx
    if slope >= 0.0:
        return 0.0
    return float(max(0.0, 1.0 - float(np.sum((a - slope * x) ** 2)) / aa))


def inertia_note(runs: Sequence, inertia: float, unit: str) -> str | None:
    """A note when an identified inertia may be a spring force in disguise; None when the runs tell them apart.

    Parameters
    ----------
    runs : sequence of AxisLog
        The prepared runs the inertia was identified on.
    inertia : float
        The identified inertia [effort s^2/length].
    unit : str
        Its unit, for the note (e.g. ``"A s^2/mm"``).

    Returns
    -------
    str or None
        One sentence naming the share and what to do, or None.
    """
    if not inertia > 0.0:
        return None
    share = spring_share(runs)
    if share < SPRING_SHARE_LIMIT:
        return None
    return (f"the inertia J = {inertia:.4g} {unit} cannot be told from a spring force on these runs: one law "
            f"a = -c x explains {100 * share:.1f} % of their acceleration (sinusoidal motion), so J may stand in "
            "for a stiffness and will not carry to other frequencies; for an effort measured at the load give "
            "--load-side (J = 0), else give the drive's inertia with --inertia J, or train on runs with other "
            "accelerations")


def axis_inertia_note(inertia: float, expected: float, unit: str, source: str = "the axis file") -> str | None:
    """A note when an identified inertia disagrees with the one the axis file gives; None when they agree.

    They disagree when one exceeds the other by more than :data:`AXIS_INERTIA_FACTOR` (an identified
    ``J = 0`` against a positive expected one included).

    Parameters
    ----------
    inertia : float
        The identified inertia [effort s^2/length].
    expected : float
        The inertia the axis file gives, in the same unit [effort s^2/length].
    unit : str
        Their unit, for the note (e.g. ``"A s^2/mm"``).
    source : str, default "the axis file"
        Where ``expected`` comes from, for the note.

    Returns
    -------
    str or None
        One sentence naming both values, their ratio and what to do, or None.
    """
    if not expected > 0.0:
        return None
    ratio = inertia / expected
    if 1.0 / AXIS_INERTIA_FACTOR <= ratio <= AXIS_INERTIA_FACTOR:
        return None
    return (f"the identified inertia J = {inertia:.4g} {unit} is {ratio:.3g} times the {expected:.4g} {unit} of "
            f"{source} (more than a factor {AXIS_INERTIA_FACTOR:g} apart): it stands in for another force (a "
            "spring, an effort measured at the load) or the axis file is wrong; give the axis file's inertia "
            "with --inertia, or --load-side for an effort measured at the load")
