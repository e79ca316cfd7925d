"""The zero-phase low-pass and central differences of :func:`greybox.data.prepare.derive`, kept running.

Offline the derivative filter runs forward over the whole log and back (``scipy.signal.sosfiltfilt``, odd
extension of 15 samples at each end, initial conditions scaled from the steady state of a unit step). A
stream cannot run the backward pass over what has not arrived, but it need not rerun the forward one: the
forward pass is carried sample by sample (its state kept from message to message, exactly the pass over
the whole log), and per message only the backward pass runs, from the newest sample back over the
look-ahead (:func:`~greybox.data.prepare.derivative_margin` samples, after which the backward pass's start
has decayed below ``1e-18``). The initial-condition factors are designed once per stream, not per call.

The kernels are compiled with numba (no fastmath); each section's update is written in the order
``sosfilt`` uses, so the forward pass gives the offline one's numbers. Their plain-Python references are
in the tests.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["sos_run", "backward_stretch", "central_difference", "ZeroPhaseStream"]


@njit(cache=True)
def sos_run(sos, state, x):
    """Run second-order sections (direct form II transposed) over ``x`` from ``state``, updating it in place.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        Sections ``b0 b1 b2 a0 a1 a2`` with ``a0 = 1``.
    state : ndarray, shape (n_sections, 2)
        Delay values before ``x[0]``; after the call, after ``x[-1]``.
    x : ndarray, shape (n,)
        Input samples (any unit).

    Returns
    -------
    ndarray, shape (n,)
        Output samples (the unit of ``x``).
    """
    out = np.empty(x.shape[0])
    for n in range(x.shape[0]):
        x_cur = x[n]
        for s in range(sos.shape[0]):
            x_new = sos[s, 0] * x_cur + state[s, 0]
            state[s, 0] = sos[s, 1] * x_cur - sos[s, 4] * x_new + state[s, 1]
            state[s, 1] = sos[s, 2] * x_cur - sos[s, 5] * x_new
            x_cur = x_new
        out[n] = x_cur
    return out


@njit(cache=True)
def backward_stretch(sos, zi, state, tail, forward):
    """The backward pass of a zero-phase filter over the forward output ``forward``, from the newest sample.

    The signal is extended past its newest sample by the odd extension of its last ``len(tail)`` raw
    values (as ``sosfiltfilt`` extends a log's end), the forward pass continued over it from a copy of
    ``state``, and the backward pass started there from ``zi`` times the last value.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        Second-order sections.
    zi : ndarray, shape (n_sections, 2)
        Steady-state delay values of a unit step (``scipy.signal.sosfilt_zi``).
    state : ndarray, shape (n_sections, 2)
        Forward delay values after the newest sample (not changed).
    tail : ndarray, shape (m + 1,)
        The newest ``m + 1`` raw samples, oldest first (``m`` = the extension's length).
    forward : ndarray, shape (k,)
        Forward output of the stretch to filter back, ending at the newest sample.

    Returns
    -------
    ndarray, shape (k,)
        The zero-phase output of the stretch.
    """
    m = tail.shape[0] - 1
    last = tail[m]
    extension = np.empty(m)
    for j in range(m):
        extension[j] = 2.0 * last - tail[m - 1 - j]
    ahead = sos_run(sos, state.copy(), extension)
    start = ahead[m - 1] if m else forward[forward.shape[0] - 1]
    back = np.empty((zi.shape[0], 2))
    for s in range(zi.shape[0]):
        back[s, 0] = zi[s, 0] * start
        back[s, 1] = zi[s, 1] * start
    sos_run(sos, back, ahead[::-1].copy())
    return sos_run(sos, back, forward[::-1].copy())[::-1].copy()


@njit(cache=True)
def central_difference(values, step, first_is_start, last_is_end):
    """Central differences of equally spaced values, as ``numpy.gradient`` takes them.

    Parameters
    ----------
    values : ndarray, shape (k,)
        Samples of a stretch (any unit), ``k >= 2``.
    step : float
        Sample time [s].
    first_is_start, last_is_end : bool
        Whether the stretch starts (ends) where the signal does: there the one-sided difference.

    Returns
    -------
    ndarray, shape (k,)
        The differences [unit/s]; NaN at an end of the stretch that is not an end of the signal.
    """
    k = values.shape[0]
    out = np.empty(k)
    for i in range(1, k - 1):
        out[i] = (values[i + 1] - values[i - 1]) / (2.0 * step)
    out[0] = (values[1] - values[0]) / step if first_is_start else np.nan
    out[k - 1] = (values[k - 1] - values[k - 2]) / step if last_is_end else np.nan
    return out


class ZeroPhaseStream:
    """One channel of a run through the zero-phase low-pass and one or two central differences.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        The low-pass (:func:`greybox.data.prepare.derivative_filter`).
    sample_time : float
        Nominal step [s].
    differences : {1, 2}
        Central differences after the filter: 1 for the acceleration of a logged velocity, 2 for the
        velocity and acceleration of a position.

    Attributes
    ----------
    needed : int
        Samples the filter needs before it can start (the odd extension and the sample it mirrors on).
    received : int
        Samples pushed.
    """

    def __init__(self, sos: np.ndarray, *, sample_time: float, differences: int):
        from scipy.signal import sosfilt_zi

        self.sos = np.ascontiguousarray(sos, dtype=np.float64)
        self.zi = np.ascontiguousarray(sosfilt_zi(self.sos))
        self.sample_time = float(sample_time)
        self.differences = int(differences)
        self.pad = 3 * (2 * self.sos.shape[0] + 1)  # sosfiltfilt's default extension
        self.needed = self.pad + 1
        self.received = 0
        self._state: np.ndarray | None = None
        self._raw = np.empty(0)  # raw samples [self._base, received)
        self._forward = np.empty(0)  # their forward output, once the filter has started
        self._base = 0

    def push(self, values: np.ndarray) -> None:
        """Take the next raw samples.

        Parameters
        ----------
        values : ndarray
            Samples in time order (the channel's unit).
        """
        values = np.asarray(values, dtype=np.float64)
        self._raw = np.concatenate((self._raw, values))
        self.received += len(values)
        if self._state is not None:
            self._forward = np.concatenate((self._forward, sos_run(self.sos, self._state, values)))
        elif self.received >= self.needed:  # the start: the odd extension before the first sample
            raw = self._raw
            head = 2.0 * raw[0] - raw[self.pad:0:-1]
            self._state = self.zi * head[0]
            sos_run(self.sos, self._state, head)
            self._forward = sos_run(self.sos, self._state, raw)

    @property
    def started(self) -> bool:
        """Whether enough samples arrived for the filter to run."""
        return self._state is not None

    def derivatives(self, first: int, stop: int, *, final: bool) -> list[np.ndarray]:
        """The differences of samples ``first`` to ``stop - 1`` of the run (numbered from its start).

        Parameters
        ----------
        first, stop : int
            The samples wanted; from then on, samples before ``first`` are no longer kept.
        final : bool
            The newest sample is the end of the run (the differences there one-sided).

        Returns
        -------
        list of ndarray
            The first difference, then (with ``differences=2``) the second, of the samples wanted.
        """
        reach = self.differences
        low = max(0, first - reach)
        k0 = low - self._base
        filtered = backward_stretch(self.sos, self.zi, self._state, self._raw[-(self.pad + 1):],
                                    self._forward[k0:])
        out = []
        values, offset = filtered, low
        for _ in range(reach):
            values = central_difference(values, self.sample_time, offset == 0, final)
            out.append(values)
        keep = max(0, stop - reach)  # what the next call may reach back to
        trim = min(keep, self.received - self.needed) - self._base
        if trim > 0:
            self._raw, self._forward, self._base = self._raw[trim:], self._forward[trim:], self._base + trim
        return [d[first - low:stop - low] for d in out]
