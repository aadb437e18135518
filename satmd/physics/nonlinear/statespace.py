"""The SATMD equations of motion (SPEC §2) in first-order form, their exact discretisation and modal filters.

State ``x = [u1, u2, q, v1, v2, ĩ]`` with ``ĩ = λ / L`` the shunt's small-signal
current (the flux over the small-signal inductance; without a saturating
inductor it is the current q'). Equations::

    m1 v1' = F - (c1+cp) v1 + cp v2 - (k1+kp) u1 + kp u2 - (e/Cp) q  [+ g on the absorber, - g on the host]
    m2 v2' = cp v1 - cp v2 + kp u1 - kp u2 + (e/Cp) q                  [- g on the absorber]
    L ĩ'   = -R q' - q/Cp - (e/Cp)(u1 - u2),   q' = ĩ                  [+ g in the shunt]

``x' = A x + B u`` with inputs ``u = [F, g_1 .. g_m]`` (one per element). Over
a sample the inputs are taken as straight lines (first-order hold), and
``x_{k+1} = Φ x_k + G0 u_k + G1 u_{k+1}`` is exact for such inputs
(``Φ = e^{AΔ}``; G0, G1 from one block matrix exponential). The linear
responses are then sums of first-order complex recursions (modes of Φ), run
by `scipy.signal.lfilter` over the whole record.
"""
from __future__ import annotations

import numpy as np

from ...errors import DataError

N_STATES = 6
STATE_NAMES = ("u1", "u2", "q", "v1", "v2", "i_lin")
_READ_ROWS = {"d": {0: -1.0, 1: 1.0}, "v": {3: -1.0, 4: 1.0}, "u1": {0: 1.0}, "v1": {3: 1.0}, "i": {5: 1.0}}


def batch_fields(rig, batch: int) -> dict:
    """The rig's fields as float arrays of shape (batch,)."""
    out = {}
    for name, value in rig.as_dict().items():
        arr = np.asarray(value, float)
        if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, batch)):
            raise DataError(f"rig field {name} has shape {arr.shape}; the integrator takes scalars or 1-D batches")
        out[name] = np.broadcast_to(arr.reshape(-1) if arr.ndim else arr, (batch,)).astype(float)
    return out


def system(rig, elements, batch: int):
    """A (batch, 6, 6) and input matrix B (batch, 6, 1 + m) for force and element inputs.

    Parameters
    ----------
    rig : Rig (scalars or 1-D arrays of length ``batch``).
    elements : sequence of NonlinearElement (their ``acts`` decide the input columns).
    batch : number of parameter sets.

    Returns
    -------
    (ndarray, ndarray)
    """
    p = batch_fields(rig, batch)
    if np.any(p["L"] <= 0):
        raise DataError("the time-domain integrator needs L > 0 (the shunt's inductance)")
    m1, m2, k1, kp, c1, cp = p["m1"], p["m2"], p["k1"], p["kp"], p["c1"], p["cp"]
    b, Cp, R, L = p["e"] / p["Cp"], p["Cp"], p["R"], p["L"]
    A = np.zeros((batch, N_STATES, N_STATES))
    A[:, 0, 3] = A[:, 1, 4] = A[:, 2, 5] = 1.0
    A[:, 3, 0], A[:, 3, 1], A[:, 3, 2] = -(k1 + kp) / m1, kp / m1, -b / m1
    A[:, 3, 3], A[:, 3, 4] = -(c1 + cp) / m1, cp / m1
    A[:, 4, 0], A[:, 4, 1], A[:, 4, 2] = kp / m2, -kp / m2, b / m2
    A[:, 4, 3], A[:, 4, 4] = cp / m2, -cp / m2
    A[:, 5, 0], A[:, 5, 1], A[:, 5, 2], A[:, 5, 5] = -b / L, b / L, -1.0 / (Cp * L), -R / L
    B = np.zeros((batch, N_STATES, 1 + len(elements)))
    B[:, 3, 0] = 1.0 / m1
    for j, el in enumerate(elements, start=1):
        if el.acts == "absorber":
            B[:, 3, j], B[:, 4, j] = 1.0 / m1, -1.0 / m2
        elif el.acts == "host":
            B[:, 3, j] = -1.0 / m1
        elif el.acts == "shunt":
            B[:, 2, j], B[:, 5, j] = 1.0, -R / L
        else:
            raise DataError(f"element {el.name}: unknown point of action {el.acts!r}")
    return A, B


def read_rows(signals) -> np.ndarray:
    """Rows C (len(signals), 6) that read the named signals from the state."""
    C = np.zeros((len(signals), N_STATES))
    for r, s in enumerate(signals):
        for col, val in _READ_ROWS[s].items():
            C[r, col] = val
    return C


def discretise(A, B, dt: float):
    """First-order-hold discretisation: Φ, G0, G1 with x_{k+1} = Φ x_k + G0 u_k + G1 u_{k+1} (exact for ramps).

    Parameters
    ----------
    A : (batch, n, n); B : (batch, n, p); dt : sample interval [s].

    Returns
    -------
    (Φ, G0, G1), shapes (batch, n, n), (batch, n, p), (batch, n, p).
    """
    batch, n, p = B.shape
    M = np.zeros((batch, n + 2 * p, n + 2 * p))
    M[:, :n, :n] = A * dt
    M[:, :n, n:n + p] = B * dt
    M[:, n:n + p, n + p:] = np.eye(p)
    from scipy.linalg import expm  # on first use: the package loads without scipy's linear algebra

    E = expm(M)
    phi, g1, g2 = E[:, :n, :n], E[:, :n, n:n + p], E[:, :n, n + p:]
    return phi, g1 - g2, g2


def slowest_decay(A) -> float:
    """Smallest decay rate -Re(λ) [1/s] over the eigenvalues of every A in the batch."""
    lam = np.linalg.eigvals(A)
    rate = float(np.min(-lam.real))
    if rate <= 0:
        raise DataError("the linear rig is not stable (an eigenvalue with Re >= 0): check its damping")
    return rate


class Modal:
    """The modal form of one discretised system: responses from rest as sums of first-order recursions.

    Parameters
    ----------
    phi, g0, g1 : (n, n), (n, p), (n, p) from `discretise` (one parameter set).
    """

    def __init__(self, phi, g0, g1):
        lam, V = np.linalg.eig(phi)
        if np.linalg.cond(V) > 1e10:
            raise DataError("the rig's modes are (nearly) repeated; the modal filter cannot separate them")
        self.lam, self.V = lam, V
        Vinv = np.linalg.inv(V)
        self.w0, self.w1 = Vinv @ g0, Vinv @ g1

    def states(self, inputs, columns=None) -> np.ndarray:
        """Modal states (n, N) for the inputs (len(columns), N) fed to those input columns, from rest.

        Parameters
        ----------
        inputs : (q, N) samples (0 before sample 0).
        columns : indices of the input columns they drive (default: all).

        Returns
        -------
        ndarray (n, N), complex
        """
        cols = slice(None) if columns is None else list(columns)
        u = np.asarray(inputs, float)
        shifted = np.zeros_like(u)
        shifted[:, 1:] = u[:, :-1]
        drive = self.w0[:, cols] @ shifted + self.w1[:, cols] @ u  # c'_k = W0 u_{k-1} + W1 u_k
        from scipy.signal import lfilter  # on first use: scipy.signal alone costs a CLI start-up

        eta = np.empty(drive.shape, complex)
        for j in range(self.lam.size):
            eta[j] = lfilter([1.0], [1.0, -self.lam[j]], drive[j])
        return eta

    def project(self, rows, eta) -> np.ndarray:
        """Real outputs rows @ x for modal states ``eta`` (rows: (o, n))."""
        return ((rows @ self.V) @ eta).real


def modal_filter(phi, g0, g1, out_rows, out_direct, inputs):
    """Outputs of the discretised linear system, from rest, for sampled inputs (one parameter set).

    Parameters
    ----------
    phi, g0, g1 : (n, n), (n, p), (n, p) from `discretise`.
    out_rows : (o, n) output rows; out_direct : (o, p) direct feed-through.
    inputs : (p, N) input samples; the inputs are 0 before sample 0 and the state is 0 there.

    Returns
    -------
    ndarray (o, N)
    """
    modal = Modal(phi, g0, g1)
    return modal.project(out_rows, modal.states(inputs)) + out_direct @ np.asarray(inputs, float)
