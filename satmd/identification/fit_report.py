"""The plain-text report of a fit: `FitResult.report` formats, nothing here computes."""
from __future__ import annotations

import math

from ..physics.rig import PARAMETER_INFO


def fit_report(result) -> str:
    """Plain-text report of a `FitResult` (in the spirit of lmfit's fit_report); it only formats.

    Parameters
    ----------
    result : FitResult

    Returns
    -------
    str
        Fit statistics, variables with std, correlations above 0.1 and warnings.
    """
    noise = ("std from the data" if result.weighted else
             "no std in the data: σ = max|x| per channel; std from the residuals (sandwich HC3)")
    lines = [
        "[[Fit statistics]]",
        f"    channels           = {', '.join(result.channels)}",
        f"    data points        = {result.n_data} (real and imaginary parts)",
        f"    free parameters    = {len(result.names)}",
        f"    function evals     = {result.nfev}",
        f"    wall time          = {result.wall_time:.3f} s",
        f"    noise model        = {noise}",
        f"    chi-square         = {result.chi2:.6g}",
        f"    reduced chi-square = {result.chi2_reduced:.6g}",
        f"    Akaike info crit   = {result.aic:.6g}",
        f"    Bayesian info crit = {result.bic:.6g}",
        f"    relative FRF error = {result.rel_error:.3e}",
        "    fit (NRMSE)        = " + ", ".join(f"{c} {v:.2f} %" for c, v in result.fit_percent.items()),
        "[[Variables]]",
    ]
    for n in result.names:
        v, s = result.values[n], result.std[n]
        unit = PARAMETER_INFO.get(n, ("", ""))[0]
        init = result.start.get(n)
        if n in result.pinned:
            spread = "(pinned at a bound: no std)"
        elif not math.isfinite(s):
            spread = "+/- ? (not identifiable)"
        else:
            spread = f"+/- {s:.3g} " + (f"({100 * s / abs(v):.3g} %)" if v else "")
        lines.append(f"    {n:<10} = {v:.8g} {spread} {unit}  (init = {init:.6g})")
    pairs = [(abs(result.correlation[i, j]), result.names[i], result.names[j], result.correlation[i, j])
             for i in range(len(result.names)) for j in range(i + 1, len(result.names))]
    pairs = sorted((p for p in pairs if p[0] > 0.1), reverse=True)
    if pairs:
        lines.append("[[Correlations]] (unreported correlations are < 0.100)")
        lines += [f"    C({a}, {b}) = {c:+.4f}" for _, a, b, c in pairs]
    if result.warnings:
        lines.append("[[Warnings]]")
        lines += [f"    {w}" for w in result.warnings]
    return "\n".join(lines)
