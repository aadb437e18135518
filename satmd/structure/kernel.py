"""The joint's force in time: one sequential pass over the samples (compiled with numba when it is there).

The structure is linear but for one joint; its modes are first-order complex states driven by a scalar
input, discretised exactly for inputs that are straight lines between samples (first-order hold):
``z_k = ψ z_{k-1} + G0 u_{k-1} + G1 u_k`` (`satmd.structure.linear.discretise`). The force's part of
the pair's relative motion (``d_F``, ``v_F``) is linear and known over the record; the joint's own part
comes from its force ``g`` through the same modes. At every sample the joint's force is the law at the
motion it makes, ``g_k = law(d_k(g_k), v_k(g_k))`` (the hold's ``G1`` term puts ``g_k`` in its own motion),
solved by Newton steps on the scalar ``g_k`` from a linear extrapolation: an implicit step that stays
stable on a stiff friction law. A term with a memory (a stick-slip contact, `laws.slide`) is stepped from its
state at the previous sample over the stroke since; its state moves on once the sample's force is found.
The same pass keeps the modes' states driven by ``g`` at the samples asked for (`joint_states`): the outputs
are linear in them, and filtering ``g`` through every mode again cost as much as the pass.
"""
from __future__ import annotations

import numpy as np

from .laws import slide, term

SLIP = 10  # `laws.TERM_CODES["slip(d)"]`: the one term with a memory (`laws.HYSTERETIC`)

NEWTON_STEPS = 20
NEWTON_TOL = 1e-10


def joint_force(psi, G0, G1, rd, rv, dF, vF, codes, coefs, aux):
    """The joint's force at every sample (see the module docstring).

    Parameters
    ----------
    psi, G0, G1 : (n,) complex: each mode's step and first-order-hold input weights
    rd, rv : (n,) complex: twice each mode's residue in the pair's relative displacement and velocity per
        unit joint force (the motion is ``Re Σ rd z``)
    dF, vF : (N,) the pair's relative displacement and velocity the force alone makes
    codes, coefs, aux : the law's terms (`satmd.structure.laws.TERM_CODES`), coefficients, shape constants

    Returns
    -------
    (N,) float: the joint's force; NaN from the first sample where it ran away (no finite solution).
    """
    return joint_states(psi, G0, G1, rd, rv, dF, vF, codes, coefs, aux, 0, 0)[0]


def joint_states(psi, G0, G1, rd, rv, dF, vF, codes, coefs, aux, first, stride):
    """`joint_force` and the modes' states the joint's force drives (``z_k = ψ z_{k-1} + G0 g_{k-1} + G1 g_k``
    from rest, as `satmd.structure.linear.modal_states` of ``g``) at samples ``first, first + stride, …``.

    Returns
    -------
    g : (N,) float, as `joint_force`
    states : (n, M) complex at the samples asked for; none (M = 0) when ``stride`` is 0
    """
    if not len(codes) == len(coefs) == len(aux):  # the compiled pass reads past an array's end unchecked
        raise ValueError(f"{len(codes)} terms, {len(coefs)} coefficients and {len(aux)} shape constants")
    args = (psi, G0, G1, rd, rv, dF, vF, codes, coefs, aux, int(first), int(stride))
    if _compiled() is not None:
        return _compiled()(*args)
    return _pass(*args)


def _law(codes, coefs, aux, d, v, state, d_last):
    """(force, ∂/∂d, ∂/∂v) at (d, v), a term with a memory stepped from its ``state`` at the stroke ``d_last``."""
    f = 0.0
    fd = 0.0
    fv = 0.0
    for j in range(codes.size):
        if codes[j] == SLIP:
            r, slope = slide(state[j], (d - d_last) / aux[j])
            t, td, tv = aux[j] * r, slope, 0.0
        else:
            t, td, tv = term(codes[j], d, v, aux[j])
        f += coefs[j] * t
        fd += coefs[j] * td
        fv += coefs[j] * tv
    return f, fd, fv


def _pass(psi, G0, G1, rd, rv, dF, vF, codes, coefs, aux, first, stride):
    n_samples = dF.size
    n_modes = psi.size
    n_kept = (n_samples - first + stride - 1) // stride if stride > 0 and n_samples > first else 0
    states = np.zeros((n_modes, n_kept), np.complex128)
    g = np.zeros(n_samples)
    z = np.zeros(n_modes, np.complex128)
    zp = np.zeros(n_modes, np.complex128)  # the states before the sample's force (no array made per sample)
    sd = 0.0
    sv = 0.0
    for r in range(n_modes):
        sd += (rd[r] * G1[r]).real
        sv += (rv[r] * G1[r]).real
    g1 = 0.0
    g2 = 0.0
    state = np.zeros(codes.size)  # each memory term's state (from rest: zero)
    d_last = 0.0
    for k in range(n_samples):
        d_known = dF[k]
        v_known = vF[k]
        for r in range(n_modes):
            zp[r] = psi[r] * z[r] + G0[r] * g1  # from rest z = 0 and g1 = 0
            d_known += (rd[r] * zp[r]).real
            v_known += (rv[r] * zp[r]).real
        x = 2.0 * g1 - g2
        for _ in range(NEWTON_STEPS):
            f, fd, fv = _law(codes, coefs, aux, d_known + sd * x, v_known + sv * x, state, d_last)
            slope = 1.0 - fd * sd - fv * sv
            step = (x - f) / slope if slope != 0.0 else 0.0
            x -= step
            if abs(step) <= NEWTON_TOL * (1.0 + abs(x)):
                break
        if not np.isfinite(x):
            g[k:] = np.nan
            return g, states
        g[k] = x
        d_now = d_known + sd * x
        for j in range(codes.size):
            if codes[j] == SLIP:
                state[j] = slide(state[j], (d_now - d_last) / aux[j])[0]
        d_last = d_now
        for r in range(n_modes):
            z[r] = zp[r] + G1[r] * x
        if stride > 0 and k >= first and (k - first) % stride == 0:
            kept = (k - first) // stride
            for r in range(n_modes):
                states[r, kept] = z[r]
        g2 = g1
        g1 = x
    return g, states


_STATE: dict = {}


def _compiled():
    """The numba-compiled pass, or None without numba (the NumPy pass is the same arithmetic, ~100x slower)."""
    from .laws import COMPILING

    with COMPILING:
        return _compile()


def _compile():
    if "pass" not in _STATE:
        try:
            import numba
        except ImportError:  # pragma: no cover - exercised where numba is absent
            _STATE["pass"] = None
        else:
            from .. import _compiled
            from . import laws

            global term, slide, _law
            sources = [__file__, laws.__file__]  # the law's text is compiled into the pass
            term = numba.njit(cache=True, fastmath=False)(term)  # _law calls it by this name
            laws.compile_slide(numba)
            slide = laws.slide
            _law = _compiled.njit_cached(numba, _law, sources)  # _pass calls it by this name
            _STATE["pass"] = _compiled.njit_cached(numba, _pass, sources)
    return _STATE["pass"]
