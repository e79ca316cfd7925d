"""A causal derivative for ``greybox live --latency low``: each sample's velocity and acceleration at once.

The exact mode derives a sample as the whole log would (:mod:`greybox.live.zerophase`): a zero-phase
low-pass that needs the samples after it, so an estimate leaves 0.368 s after its sample (at 2 ms, 50 Hz).
The low-latency mode runs a 4th-order Butterworth low-pass (:func:`greybox.data.prepare.derivative_filter`)
forward only, from the steady state of the run's first value, and takes backward differences of its output:
a sample's derivatives need nothing after it, and its estimate goes out with the message that brought it.

Its cut-off is :data:`CAUSAL_CUTOFF_FRACTION` of the Nyquist frequency (:func:`causal_cutoff`: 225 Hz at 2 ms),
unless one is given: a causal filter's delay grows as its cut-off falls, and the estimate follows the delayed
derivatives. The fraction was chosen on development data (the twin's cutting logs of seeds 7 and 11, datasets C
and D, position only and with the velocity logged, and the independent split's ``cut_D``): among the cut-offs
0.2, 0.4, 0.6, 0.8 and 0.9 of the Nyquist frequency, with and without the lead below, the one whose mean cut
force lay nearest the exact mode's on the worst of those cuts.

A derived velocity (a stream of position only) is moreover led by its own low-frequency delay: it is given as
``first + lead * second`` with ``lead`` the delay of the first difference (a first-order prediction from the
second difference), so that its delay at low frequencies is zero to first order; the acceleration is not led.

The price is a delay of the derived acceleration: at low frequencies (the feed motion) the low-pass's group
delay at zero frequency, plus half a step for each backward difference (:func:`group_delay_samples`). At 2 ms
and 225 Hz: 0.71 samples (1.41 ms) for the acceleration of a logged velocity, 1.21 samples (2.41 ms) for that of
a position, whose velocity is not delayed at low frequencies (to first order). The logged channels (position,
current, a logged velocity) are not delayed.

The kernel is compiled with numba; its plain-Python reference is in the tests.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["CAUSAL_CUTOFF_FRACTION", "causal_cutoff", "causal_differences", "group_delay_samples", "CausalStream"]

#: Cut-off of the causal low-pass as a fraction of the Nyquist frequency (chosen on development data, above).
CAUSAL_CUTOFF_FRACTION = 0.9


def causal_cutoff(sample_time: float) -> float:
    """The default cut-off of the causal low-pass [Hz]: :data:`CAUSAL_CUTOFF_FRACTION` of the Nyquist frequency.

    Parameters
    ----------
    sample_time : float
        Nominal step [s].
    """
    return CAUSAL_CUTOFF_FRACTION * 0.5 / float(sample_time)


@njit(cache=True)
def causal_differences(sos, state, previous, x, step, differences, lead):
    """Low-pass ``x`` causally and take one or two backward differences, carrying the state in place.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        Second-order sections ``b0 b1 b2 a0 a1 a2`` with ``a0 = 1``.
    state : ndarray, shape (n_sections, 2)
        Delay values (direct form II transposed) before ``x[0]``; after the call, after ``x[-1]``.
    previous : ndarray, shape (2,)
        The filtered value and its first difference at the sample before ``x[0]``; updated.
    x : ndarray, shape (n,)
        Raw samples (any unit).
    step : float
        Sample time [s].
    differences : int
        1 or 2.
    lead : float
        With 2 differences, the first is given as ``first + lead * second``: its low-frequency delay
        shortened by ``lead`` [s] (a first-order prediction); 0 leaves it as it is.

    Returns
    -------
    ndarray, shape (differences, n)
        The first difference [unit/s] (led by ``lead``), then (with 2) the second [unit/s^2].
    """
    n = x.shape[0]
    out = np.empty((differences, n))
    for k in range(n):
        x_cur = x[k]
        for s in range(sos.shape[0]):
            x_new = sos[s, 0] * x_cur + state[s, 0]
            state[s, 0] = sos[s, 1] * x_cur - sos[s, 4] * x_new + state[s, 1]
            state[s, 1] = sos[s, 2] * x_cur - sos[s, 5] * x_new
            x_cur = x_new
        first = (x_cur - previous[0]) / step
        out[0, k] = first
        if differences == 2:
            second = (first - previous[1]) / step
            out[0, k] = first + lead * second
            out[1, k] = second
        previous[0] = x_cur
        previous[1] = first
    return out


def group_delay_samples(sos: np.ndarray, differences: int) -> float:
    """The delay of the ``differences``-th causal derivative at low frequencies, in samples.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        The low-pass.
    differences : int
        Backward differences after it (each adds half a step).

    Returns
    -------
    float
        The low-pass's group delay at zero frequency plus ``differences / 2`` [samples].
    """
    from scipy.signal import group_delay

    delay = 0.0
    for section in np.asarray(sos, dtype=np.float64):
        delay += float(group_delay((section[:3], section[3:]), w=[1e-6])[1][0])
    return delay + 0.5 * differences


class CausalStream:
    """One channel of a run through the causal low-pass and one or two backward differences.

    The same interface as :class:`~greybox.live.zerophase.ZeroPhaseStream`, without a look-ahead: the
    derivatives of every sample pushed are ready at once.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        The low-pass (:func:`greybox.data.prepare.derivative_filter`).
    sample_time : float
        Nominal step [s].
    differences : {1, 2}
        1 for the acceleration of a logged velocity, 2 for the velocity and acceleration of a position.

    Attributes
    ----------
    needed : int
        Samples needed before the filter can start (1).
    received : int
        Samples pushed.
    lead : float
        With 2 differences, the lead of the velocity: the low-frequency delay of the first difference [s]
        (its delay is then zero to first order); 0 with 1 difference.
    delay : float
        Group delay of the last derivative (the acceleration) at low frequencies [samples]
        (:func:`group_delay_samples`).
    """

    needed = 1

    def __init__(self, sos: np.ndarray, *, sample_time: float, differences: int):
        from scipy.signal import sosfilt_zi

        self.sos = np.ascontiguousarray(sos, dtype=np.float64)
        self.zi = np.ascontiguousarray(sosfilt_zi(self.sos))
        self.sample_time = float(sample_time)
        self.differences = int(differences)
        self.lead = group_delay_samples(self.sos, 1) * self.sample_time if self.differences == 2 else 0.0
        self.delay = group_delay_samples(self.sos, self.differences)
        self.received = 0
        self._state: np.ndarray | None = None
        self._previous = np.zeros(2)
        self._out = np.empty((self.differences, 0))  # derivatives of samples [self._base, received)
        self._base = 0

    @property
    def started(self) -> bool:
        """Whether a sample arrived."""
        return self._state is not None

    def push(self, values: np.ndarray) -> None:
        """Take the next raw samples and derive them.

        Parameters
        ----------
        values : ndarray
            Samples in time order (the channel's unit).
        """
        values = np.ascontiguousarray(values, dtype=np.float64)
        if not values.size:
            return
        if self._state is None:  # the steady state of the first value: no motion before the run
            self._state = self.zi * values[0]
            self._previous[0] = values[0]
        out = causal_differences(self.sos, self._state, self._previous, values, self.sample_time, self.differences,
                                 self.lead)
        self._out = np.concatenate((self._out, out), axis=1)
        self.received += values.size

    def derivatives(self, first: int, stop: int, *, final: bool) -> list[np.ndarray]:
        """The derivatives of samples ``first`` to ``stop - 1`` of the run; those before ``stop`` are then dropped.

        Parameters
        ----------
        first, stop : int
            The samples wanted (numbered from the run's start).
        final : bool
            Whether the newest sample ends the run (no difference for a causal filter).

        Returns
        -------
        list of ndarray
            The first derivative, then (with ``differences=2``) the second.
        """
        out = [row[first - self._base:stop - self._base].copy() for row in self._out]
        self._out, self._base = self._out[:, stop - self._base:], stop
        return out
