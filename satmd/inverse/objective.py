"""The physics-consistent objective of eq. 22 and its Gauss-Newton preconditioner (needs torch).

Outputs are normalised (R, L) of any leading shape (..., n, 2); targets are
complex FRFs (..., n, 2, F) that broadcast against them: one target set for
every ensemble member (n, 2, F), or one per member (E, n, 2, F) when members
train on different samples (cross-fitting, `satmd.inverse.training`).

`ShuntMobius` evaluates the same residuals and the same Gauss-Newton step
without a twin call per step (the default ``jacobian="mobius"``); the twin
functions here are the reference it is checked against and the fallback.
"""
from __future__ import annotations

try:
    import torch
except ImportError as exc:  # pragma: no cover
    raise ImportError("satmd.inverse needs torch: pip install 'satmd[nn]'") from exc

from ..conventions import ACCEL_CHANNELS
from ..physics import Rig
from ..physics.torch import frf as torch_frf
from .dataset import BOUNDS

import numpy as np

MAX_STEP = 0.05  # largest Gauss-Newton step per output (normalised units)
FD_STEP = {"complex128": 1e-6, "complex64": 1e-3}  # finite-difference step of the Jacobian, per twin precision


def real_of(dtype):
    """The real dtype of a complex twin dtype."""
    return torch.float64 if dtype == torch.complex128 else torch.float32


def _denormalised(out, bounds):
    r_lo, r_hi = bounds["R"]
    l_lo, l_hi = bounds["L"]
    return r_lo + out[..., 0] * (r_hi - r_lo), l_lo + out[..., 1] * (l_hi - l_lo)


def _complex_residuals(norm_out, target, s_n, freq_t, rig, bounds):
    """Scaled complex residuals of eq. 22, (..., n, 2F): [d1, d2] / s_n (the twin in the targets' dtype)."""
    R, L = _denormalised(norm_out, bounds)
    pred = torch_frf(freq_t, rig.replace(R=R, L=L), dtype=target.dtype, device=freq_t.device, outputs=ACCEL_CHANNELS)
    return torch.cat([pred["a1"] - target[..., 0, :], pred["a2"] - target[..., 1, :]], dim=-1) * (1.0 / s_n)[..., None]


def _residuals(norm_out, target, s_n, freq_t, rig, bounds, dtype):
    """Scaled real residual vector of eq. 22, (..., n, 4F): [Re d1, Re d2, Im d1, Im d2] / s_n."""
    d = _complex_residuals(norm_out, target.to(dtype), s_n, freq_t, rig, bounds)
    return torch.cat([d.real, d.imag], dim=-1)


def physics_loss(norm_out, target, s_n, freq_t, rig: Rig, bounds=BOUNDS, dtype=torch.complex128):
    """Eq. 22 for normalised outputs (..., n, 2) against complex targets (..., n, 2, F); per sample, shape (..., n)."""
    r = _residuals(norm_out.to(real_of(dtype)), target, s_n, freq_t, rig, bounds, dtype)
    return (r * r).sum(dim=-1) / freq_t.numel()


def gauss_newton_step(norm_out, target, s_n, freq_t, rig, bounds=BOUNDS, dtype=torch.complex128,
                      damping: float = 1e-3):
    """Per-sample Gauss-Newton step of eq. 22 in the normalised outputs, and the loss.

    Returns ``(step, loss)``, shapes (..., n, 2) and (..., n). R and L enter
    the model only through the series shunt impedance ``Zs = R + iωL`` (SPEC
    §2), on which the accelerations depend holomorphically, so at each
    frequency ``dA/dL = iω dA/dR``: one forward difference in R (the point and
    its nudge in *one* twin call) gives the whole Jacobian. The two columns
    are then orthogonal in the real residual space (``Re(conj(z) iωz) = 0``),
    so the 2x2 normal equations (with Levenberg-Marquardt damping) are
    diagonal. `gauss_newton_step_fd` is the same step with both columns by
    forward differences (one more twin evaluation).
    """
    h = FD_STEP["complex128" if dtype == torch.complex128 else "complex64"]
    with torch.no_grad():
        o = norm_out.detach().to(real_of(dtype))
        nudge = torch.tensor([h, 0.0], dtype=o.dtype, device=o.device)
        d = _complex_residuals(torch.stack([o, o + nudge]), target.to(dtype), s_n, freq_t, rig, bounds)
        d0, jr = d[0], (d[1] - d[0]) * (1.0 / h)
        # the L column is i w jr, w = ω span_L / span_R per point (both channels)
        span = (bounds["L"][1] - bounds["L"][0]) / (bounds["R"][1] - bounds["R"][0])
        w = (2 * torch.pi * span) * freq_t.repeat(2)
        jr2 = jr.real * jr.real + jr.imag * jr.imag
        g = jr.conj() * d0
        a = jr2.sum(-1) * (1 + damping) + 1e-30
        c = (jr2 * (w * w)).sum(-1) * (1 + damping) + 1e-30
        step = torch.stack([g.real.sum(-1) / a, (g.imag * w).sum(-1) / c], dim=-1)
    return step, (d0.real * d0.real + d0.imag * d0.imag).sum(-1) / freq_t.numel()


def gauss_newton_step_fd(norm_out, target, s_n, freq_t, rig, bounds=BOUNDS, dtype=torch.complex128,
                         damping: float = 1e-3):
    """`gauss_newton_step` with the R and L columns both by forward differences (three points in one twin call)."""
    h = FD_STEP["complex128" if dtype == torch.complex128 else "complex64"]
    with torch.no_grad():
        o = norm_out.detach().to(real_of(dtype))
        nudge = torch.eye(2, dtype=o.dtype, device=o.device) * h
        r = _residuals(torch.stack([o, o + nudge[0], o + nudge[1]]), target, s_n, freq_t, rig, bounds, dtype)
        # products, not divisions: a division costs several multiplications here
        r0, jr, jl = r[0], (r[1] - r[0]) * (1.0 / h), (r[2] - r[0]) * (1.0 / h)
        a = (jr * jr).sum(-1) * (1 + damping) + 1e-30
        b = (jr * jl).sum(-1)
        c = (jl * jl).sum(-1) * (1 + damping) + 1e-30
        gr, gl = (jr * r0).sum(-1), (jl * r0).sum(-1)
        det = a * c - b * b
        step = torch.stack([(c * gr - b * gl) / det, (a * gl - b * gr) / det], dim=-1)
    return step, (r0 * r0).sum(-1) / freq_t.numel()


def physics_objective(out, target, s_n, freq_t, rig, bounds=BOUNDS, dtype=torch.complex128,
                      precondition: bool = True, jacobian: str = "shunt"):
    """``(objective, loss)`` of the network outputs ``out`` (..., n, 2): ``objective.backward()`` trains.

    With ``precondition`` the objective is the surrogate ``sum(out * step) / n``
    whose gradient is each sample's Gauss-Newton step (clipped at `MAX_STEP`):
    the minimiser of eq. 22 is unchanged, but R converges as fast as L.
    Otherwise it is eq. 22 itself, differentiated through the twin.
    ``jacobian``: "shunt" (`gauss_newton_step`) or "fd" (`gauss_newton_step_fd`).
    ``loss`` is the mean eq. 22 value (detached).
    """
    if not precondition:
        loss = physics_loss(out, target, s_n, freq_t, rig, bounds, dtype).mean()
        return loss, loss.detach()
    gn_step = gauss_newton_step_fd if jacobian == "fd" else gauss_newton_step
    step, loss = gn_step(out, target, s_n, freq_t, rig, bounds, dtype)
    step = step.clamp(-MAX_STEP, MAX_STEP).to(out.dtype) / out[..., 0].numel()
    return (out * step).sum(), loss.mean()


class ShuntMobius:
    """The twin's accelerations as Möbius maps of the shunt impedance, fitted once per rig and grid.

    R and L enter the model only through ``Zs = R + iωL`` (SPEC §2), which
    enters one entry of the system matrix linearly, so at each frequency
    each acceleration is a Möbius map ``A(Zs) = (a Zs + b) / (c Zs + 1)``.
    `fit` takes the three coefficients per channel and frequency from three
    twin evaluations (complex128) and checks the map against the twin at
    further points; a rig that the map does not reproduce to ``TOL`` gets
    None (the caller keeps the twin). Evaluating the map and its derivative
    ``A' = (a - c A) / (c Zs + 1)`` exactly (no finite difference) costs a
    few complex operations per point, where the twin path costs two twin
    evaluations per training step.
    """

    ANCHORS = ((5.0, 0.02), (50.0, 0.25), (100.0, 0.45))  # (R [Ω], L [H]) of the three fitting points
    CHECKS = ((20.0, 0.40), (80.0, 0.05), (0.5, 0.001), (103.0, 0.5), (35.0, 0.19))
    TOL = 1e-8  # largest |map - twin| / max |twin| at the check points (complex128)

    def __init__(self, coef, omega, bounds, dtype):
        self.a, self.b, self.c = (coef[..., k].to(dtype) for k in range(3))  # each (2, F)
        self.omega = omega.to(real_of(dtype))
        self.bounds = bounds
        self.span_r = float(bounds["R"][1] - bounds["R"][0])
        # the L column of the Jacobian is i w times the R column, w = ω span_L / span_R (per frequency)
        self.w = self.omega * float((bounds["L"][1] - bounds["L"][0]) / self.span_r)
        self.n_freq = omega.numel()

    @classmethod
    def fit(cls, freq_t, rig: Rig, bounds=BOUNDS, dtype=torch.complex64):
        """The map for ``rig`` on the grid ``freq_t`` (a real tensor), or None where the twin is not of this form."""
        freq = freq_t.detach().to(torch.float64)
        omega = 2 * np.pi * freq.cpu().numpy()

        def twin(points):
            p = np.asarray(points, float)
            out = torch_frf(freq.cpu(), rig.replace(R=p[:, 0], L=p[:, 1]), dtype=torch.complex128, outputs=ACCEL_CHANNELS)
            return np.stack([out["a1"].numpy(), out["a2"].numpy()], axis=1)  # (k, 2, F)

        def zs(points):
            p = np.asarray(points, float)
            return (p[:, 0, None] + 1j * omega * p[:, 1, None])[:, None, :]  # (k, 1, F)

        z, w = np.broadcast_arrays(zs(cls.ANCHORS), twin(cls.ANCHORS))
        # a z + b - c z w = w at the three anchors: one 3x3 system per channel and frequency
        system = np.moveaxis(np.stack([z, np.ones_like(w), -z * w], axis=-1), 0, -2)  # (2, F, 3, 3)
        with np.errstate(all="ignore"):
            try:
                coef = np.linalg.solve(system, np.moveaxis(w, 0, -1)[..., None])[..., 0]  # (2, F, 3)
            except np.linalg.LinAlgError:
                return None
            zc, wc = zs(cls.CHECKS), twin(cls.CHECKS)
            mapped = (coef[..., 0] * zc + coef[..., 1]) / (coef[..., 2] * zc + 1)
            err = np.max(np.abs(mapped - wc)) / np.max(np.abs(wc))
        if not np.isfinite(err) or err > cls.TOL:
            return None
        return cls(torch.as_tensor(coef, device=freq_t.device), torch.as_tensor(omega, device=freq_t.device),
                   bounds, dtype)

    def residuals(self, norm_out, target, s_n):
        """Scaled complex residuals (..., n, 2, F) ``(A - target) / s_n``, the map's ``A'`` and ``1/s_n``."""
        R, L = _denormalised(norm_out.to(self.omega.dtype), self.bounds)
        z = torch.complex(R[..., None], L[..., None] * self.omega).unsqueeze(-2)  # (..., n, 1, F)
        inv_d = 1.0 / (self.c * z + 1)
        acc = (self.a * z + self.b) * inv_d
        inv_s = (1.0 / s_n)[..., None, None]
        return (acc - target) * inv_s, (self.a - self.c * acc) * inv_d, inv_s

    def physics_loss(self, norm_out, target, s_n):
        """Eq. 22 per sample (..., n), differentiable (as `physics_loss`)."""
        d, _, _ = self.residuals(norm_out, target, s_n)
        return (d.real * d.real + d.imag * d.imag).sum(dim=(-2, -1)) / self.n_freq

    def gauss_newton_step(self, norm_out, target, s_n, damping: float = 1e-3):
        """`gauss_newton_step` with the map's exact derivative: ``(step, loss)``, (..., n, 2) and (..., n)."""
        with torch.no_grad():
            d, dacc, inv_s = self.residuals(norm_out.detach(), target, s_n)
            jr = dacc * (inv_s * self.span_r)  # d residual / d normalised R
            jr2 = jr.real * jr.real + jr.imag * jr.imag
            g = jr.conj() * d
            a = jr2.sum(dim=(-2, -1)) * (1 + damping) + 1e-30
            c = (jr2 * (self.w * self.w)).sum(dim=(-2, -1)) * (1 + damping) + 1e-30
            step = torch.stack([g.real.sum(dim=(-2, -1)) / a, (g.imag * self.w).sum(dim=(-2, -1)) / c], dim=-1)
            loss = (d.real * d.real + d.imag * d.imag).sum(dim=(-2, -1)) / self.n_freq
        return step, loss
