"""Use case III end to end: the analyses of a trained net and the symbolic distillation, as typed results.

`neural_analysis` and `symbolic_analysis` compute; `satmd.report.explain_text`
formats them (markdown and figures) for ``satmd explain``, the ``satmd
reproduce`` section and ``examples/uc3_explain.py``.
"""
from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..physics import frf
from . import contract
from .anova import GridAnova, grid_anova, grid_ceiling
from .attributions import BLIND_CASES, OUTPUTS, PAPER_TABLE3, attribution, in_paper_bands
from .descriptors import MODAL_NAMES, grid_rig, modal_physics, xi_dataset
from .distillation import DEFAULT_SEARCH, DistillResult, distill, paper_formula_result
from .latent import LatentMap
from .sensitivity import agreement, chain_rule_check, physical_sensitivity
from .symbolic import PAPER_FORMULA, PAPER_METRICS, paper_complexity

#: Search of the ξ fit (SPEC §6 data): two short operon searches pooled with the skeleton
#: pass (a beam over products of up to three factors, plus linear or curved terms, within the
#: node budget: `satmd.explain.skeletons`), the formula shortlisted on a validation part of the
#: training rows and picked by 5-fold CV among the ten best; about 55 s on one core. time_limit
#: caps the search (operon gets operon_share of it; the skeleton pass needs about 25 s of its 56).
XI_SEARCH = {k: v for k, v in DEFAULT_SEARCH.items() if k != "max_complexity"}  # distill's own default
XI_SEARCH_QUICK = {**XI_SEARCH, "restarts": 1, "generations": 10, "time_limit": 25}
#: operon on its own, as before the skeleton pass (kept for comparison in the benchmark).
XI_OPERON = {"allowed_symbols": "add,sub,mul,div,square,exp,constant,variable", "max_length": 18, "max_depth": 8,
             "generations": 40, "population_size": 1000, "optimizer_iterations": 10, "time_limit": 55}
#: The modal descriptors: node budget (issue 15) and search.
MODAL_CAP = 15
MODAL_SEARCH = {"backend": "hybrid", "validation": 0.2, "time_limit": 45, "operon_share": 0.5, "max_length": 14,
                "max_depth": 8, "generations": 100, "population_size": 300, "optimizer_iterations": 5,
                "search_samples": 1000}
MODAL_SEARCH_QUICK = {**MODAL_SEARCH, "generations": 20, "time_limit": 10}
COMPLEXITY_CAP = 30
SPACES = ("raw", "scaled")
AGREEMENT_KEYS = ("cosine_R", "spearman_R", "cosine_L", "spearman_L")
TRIPLES = ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))  # input subsets for the three-input ceilings


def case_labels(cases=BLIND_CASES):
    return [f"R={r:g} Ω, L={l:g} H" for r, l in cases]


def blind_frfs(model, cases=BLIND_CASES) -> np.ndarray:
    """Noise-free (n, 2, F) accelerations of the blind pairs on the model's grid (as the paper's)."""
    cases = np.asarray(cases, float)
    rig = contract.model_rig(model).replace(R=cases[:, 0], L=cases[:, 1])
    r = frf(model.freq_hz, rig, outputs=ACCEL_CHANNELS)
    return np.stack([r.channel(c) for c in ACCEL_CHANNELS], axis=1)


@dataclass(frozen=True)
class NeuralAnalysis:
    """Attribution, Table 3, physical sensitivity, agreement, chain rule and latent map of one net.

    Every mapping keyed by space holds "raw" and "scaled" (`SPACES`).
    """

    labels: list  # blind case names
    attributions: dict  # space -> `Attribution`
    table3: dict  # space -> {"R": stats, "L": stats}
    in_bands: dict  # space -> {"R": bool, "L": bool}: peaks inside the paper's bands
    physical: dict  # space -> PhysicalSensitivity
    agreement: dict  # space -> one dict per case (cosine_R, spearman_R, ...)
    agreement_mean: dict  # space -> mean over the cases
    chain: np.ndarray  # (n, 2, 2) G J diag(span)
    span: np.ndarray  # output ranges
    latent: LatentMap

    def to_dict(self) -> dict:
        return {
            "table3": self.table3["raw"], "table3_scaled": self.table3["scaled"], "paper_table3": PAPER_TABLE3,
            "peaks_in_paper_bands": self.in_bands, "agreement": self.agreement["raw"],
            "agreement_scaled": self.agreement["scaled"], "agreement_mean": self.agreement_mean,
            "chain_rule": self.chain.tolist(), "latent": self.latent.to_dict(),
            "blind_prediction": self.attributions["raw"].prediction.tolist(),
        }


def neural_analysis(model, quick: bool = False, latent_data=None) -> NeuralAnalysis:
    """All analyses of a trained net (see `NeuralAnalysis`).

    Parameters
    ----------
    model : a trained net following `satmd.explain.contract.ExplainableModel`.
    quick : smaller latent set and sweeps.
    latent_data : labelled FRFs for the latent map (default: the preset's jittered pairs).

    Returns
    -------
    NeuralAnalysis
    """
    from .latent import latent_map

    contract.check_net_model(model)
    cases = np.asarray(BLIND_CASES, float)
    labels = case_labels()
    a = blind_frfs(model)
    att = {sp: attribution(model, a, labels, space=sp) for sp in SPACES}
    t3 = {sp: att[sp].table3() for sp in SPACES}
    in_bands = {sp: {o: in_paper_bands(t3[sp][o]["peaks_hz"]) for o in OUTPUTS} for sp in SPACES}
    rig = contract.model_rig(model).replace(R=cases[:, 0], L=cases[:, 1])
    scale = np.asarray(model.scaler_.scale, float)
    phys = {"raw": physical_sensitivity(rig, model.freq_hz),
            "scaled": physical_sensitivity(rig, model.freq_hz, feature_scale=scale)}
    rows = {sp: agreement(att[sp].curves, phys[sp].curves, labels) for sp in SPACES}
    span = contract.bounds_span(model)
    chain = chain_rule_check(att["raw"].gradients, phys["raw"].jacobian, span)
    mean = {sp: {k: float(np.mean([r[k] for r in rows[sp]])) for k in AGREEMENT_KEYS} for sp in SPACES}
    if latent_data is None:
        latent_data = _latent_data(model, quick)
    lm = latent_map(model, latent_data, anchors=BLIND_CASES, n_sweep=7 if quick else 11)
    return NeuralAnalysis(labels=labels, attributions=att, table3=t3, in_bands=in_bands, physical=phys,
                          agreement=rows, agreement_mean=mean, chain=chain, span=span, latent=lm)


def _latent_data(model, quick):
    """Labelled FRFs for the latent map: the paper preset's jittered pairs (all partitions)."""
    from ..inverse import make_dataset

    return make_dataset(getattr(model, "preset", "paper"), samples_per_pair=8 if quick else 30,
                        n_samples=600 if quick else 3000, seed=int(getattr(model, "seed", 0)) + 101,
                        freq_hz=model.freq_hz, rig=contract.model_rig(model))


@dataclass(frozen=True)
class ModalDistillation:
    """One modal descriptor distilled: the formula, a cubic polynomial for scale, and what physics says.

    ``physics_r2``: R² of the undamped-physics value (no fit; `modal_reference`);
    ``switching``: share of the grid's rigs whose descriptor follows another
    mode (or anti-resonance) than the most common one: a piecewise target.
    """

    samples: int  # finite rows
    formula: DistillResult
    cubic: DistillResult
    ceiling_without_R: float
    physics: str = ""
    physics_r2: float = float("nan")
    switching: float = 0.0

    def reason(self, cap: int = 15, target: float = 0.99) -> str:
        """Why the formula stops short of ``target`` (empty when it does not)."""
        if self.formula.r2_test >= target:
            return ""
        parts = []
        if self.switching > 0.01:
            parts.append(f"on {self.switching:.0%} of the grid it follows another mode than elsewhere "
                         "(the two highest peaks change identity as L moves the electrical mode through the band), "
                         "so it is piecewise")
        cubic = self.cubic.r2_test
        parts.append(f"even a cubic polynomial in all four inputs (35 terms, several times {cap} nodes) reaches only "
                     f"test R² {cubic:.3f}, so a smooth formula of this size stops well short" if cubic < target else
                     f"a cubic polynomial in all four inputs reaches test R² {cubic:.3f}, but with 35 terms, "
                     f"several times {cap} nodes")
        return "; ".join(parts)

    def to_dict(self) -> dict:
        return {**self.formula.to_dict(), "sindy_cubic_r2_test": self.cubic.r2_test,
                "ceiling_without_R": self.ceiling_without_R, "physics": self.physics,
                "physics_r2": self.physics_r2, "switching": self.switching, "reason": self.reason()}


def modal_reference(name: str, targets: dict, physics: dict) -> tuple:
    """(what the undamped physics says, its R² against the descriptor, share switching).

    Resonances: the undamped mode nearest each rig's peak; the splitting: their
    difference; the anti-resonance: the root of the blocked-absorber
    determinant nearest the middle of the two peaks (roots and modes interlace,
    so one or two lie between them). ``attenuation_db`` has
    no undamped counterpart (it is set by damping): ("", nan, 0).
    """
    y = np.asarray(targets[name], float)
    modes = physics["f_modes_hz"]
    if name in ("f1_hz", "f2_hz", "splitting_hz"):
        picks = {}
        for peak in ("f1_hz", "f2_hz"):
            t = np.nan_to_num(np.asarray(targets[peak], float))
            picks[peak] = np.argmin(np.abs(modes - t[:, None]), axis=1)
        f = {k: np.take_along_axis(modes, v[:, None], 1)[:, 0] for k, v in picks.items()}
        if name == "splitting_hz":
            pred, idx, label = f["f2_hz"] - f["f1_hz"], picks["f2_hz"] * 3 + picks["f1_hz"], \
                "difference of the undamped modes nearest the two peaks"
        else:
            pred, idx, label = f[name], picks[name], "undamped natural frequency nearest the peak"
    elif name == "f_anti_hz":
        roots = physics["f_anti_roots_hz"]
        mid = 0.5 * np.nan_to_num(np.asarray(targets["f1_hz"], float) + np.asarray(targets["f2_hz"], float))
        idx = np.argmin(np.abs(roots - mid[:, None]), axis=1)
        pred, label = np.take_along_axis(roots, idx[:, None], 1)[:, 0], \
            "undamped anti-resonance (blocked absorber + shunt) nearest the middle of the two peaks"
    else:
        return "", float("nan"), 0.0
    ok = np.isfinite(y) & np.isfinite(pred)
    sst = float(np.sum((y[ok] - y[ok].mean()) ** 2)) or 1.0
    r2 = 1.0 - float(np.sum((y[ok] - pred[ok]) ** 2)) / sst
    counts = np.bincount(idx[ok])
    return label, r2, float(1.0 - counts.max() / ok.sum())


@dataclass(frozen=True)
class SymbolicAnalysis:
    """ξ_FRF (and the modal descriptors) distilled into formulas, with the references they are judged by."""

    backend: str
    n_threads: int
    X: np.ndarray  # SPEC §6 inputs (R, L, m2, kp)
    y: np.ndarray  # ξ
    names: tuple
    cap: int  # nodes of the paper's formula
    paper: dict  # the paper's formula on our data and split
    xi: DistillResult  # at most ``cap`` nodes
    plus1: Mapping | None  # best test R² at ≤ cap + 1 nodes (a ParetoEntry)
    best30: Mapping | None  # best test R² at ≤ COMPLEXITY_CAP nodes
    sindy: dict  # degree -> DistillResult
    ceilings: dict  # input-name triple -> R² any function of it can reach
    anova: GridAnova
    modal: dict = field(default_factory=dict)  # descriptor -> ModalDistillation
    seconds: float = 0.0

    @property
    def best_triple(self) -> tuple:
        return max(self.ceilings, key=lambda k: self.ceilings[k])

    def to_dict(self) -> dict:
        out: dict = {"paper_formula": {"expression": PAPER_FORMULA,
                                 **{k: v for k, v in self.paper.items() if k != "expression"}},
               "paper_reported": PAPER_METRICS, "xi": self.xi.to_dict(),
               "best_within_30": None if self.best30 is None
               else {**self.best30, "expression": str(self.best30["expression"])},
               "sindy": {str(d): s.to_dict() for d, s in self.sindy.items()},
               "three_input_ceiling": {", ".join(k): v for k, v in self.ceilings.items()},
               "anova": self.anova.to_dict()}
        if self.modal:
            out["modal"] = {name: m.to_dict() for name, m in self.modal.items()}
        out["seconds"] = self.seconds
        return out


def symbolic_analysis(backend: str = "hybrid", quick: bool = False, n_threads: int = 1,
                      modal: bool = True) -> SymbolicAnalysis:
    """ξ_FRF and the modal descriptors distilled into formulas (see `SymbolicAnalysis`).

    Parameters
    ----------
    backend : "hybrid" (operon and the skeleton pass), "operon", "skeleton", "pysr" or "sindy".
    quick : shorter searches.
    n_threads : threads of the symbolic search.
    modal : also distill the modal descriptors (at most `MODAL_CAP` nodes).

    Returns
    -------
    SymbolicAnalysis
    """
    t0 = time.perf_counter()
    data = xi_dataset(modal=modal)
    X, y = data.X, data.targets["xi"]
    names = data.names
    cap = paper_complexity()
    paper = paper_formula_result(X, y)
    res = distill(X, y, names=names, max_complexity=cap, n_threads=n_threads, **search_settings(backend, quick))
    sindy = {deg: distill(X, y, backend="sindy", names=names, degree=deg) for deg in ((2,) if quick else (2, 3))}
    ceilings = {tuple(names[j] for j in c): grid_ceiling(X, y, c) for c in TRIPLES}
    plus1 = res.best_within(cap + 1)
    modal_results = {}
    if modal:
        physics = modal_physics(grid_rig()[0])
        for name in MODAL_NAMES:
            if name == "peak_db":
                continue
            t = data.targets[name]
            label, r2, switching = modal_reference(name, data.targets, physics)
            modal_results[name] = ModalDistillation(
                samples=int(np.isfinite(t).sum()),
                formula=distill(X, t, names=names, max_complexity=MODAL_CAP, n_threads=n_threads,
                                **search_settings(backend, quick, modal=True)),
                cubic=distill(X, t, backend="sindy", names=names, degree=3),
                ceiling_without_R=grid_ceiling(X, t, (1, 2, 3)), physics=label, physics_r2=r2, switching=switching)
    return SymbolicAnalysis(backend=backend, n_threads=n_threads, X=X, y=y, names=names, cap=cap, paper=paper,
                            xi=res, plus1=plus1 if plus1 is not None and plus1["complexity"] > res.complexity else None,
                            best30=res.best_within(COMPLEXITY_CAP), sindy=sindy, ceilings=ceilings,
                            anova=grid_anova(X, y, names), modal=modal_results, seconds=time.perf_counter() - t0)


def search_settings(backend: str = "hybrid", quick: bool = False, modal: bool = False) -> dict:
    """`distill` keywords of the ξ (or modal) search for ``backend``.

    Parameters
    ----------
    backend : "hybrid", "operon", "skeleton", "pysr" or "sindy".
    quick : the shorter search.
    modal : the modal descriptors' search instead of ξ's.

    Returns
    -------
    dict
        Including ``backend``.
    """
    full: dict = (MODAL_SEARCH_QUICK if quick else MODAL_SEARCH) if modal else (XI_SEARCH_QUICK if quick else XI_SEARCH)
    if backend == "hybrid":
        return dict(full)
    if backend == "operon":
        keep = ("allowed_symbols", "max_length", "max_depth", "generations", "population_size",
                "optimizer_iterations", "search_samples", "time_limit", "restarts", "validation")
        return {"backend": "operon", **{k: v for k, v in full.items() if k in keep}}
    if backend == "skeleton":
        return {"backend": "skeleton", "validation": full["validation"],
                "time_limit": full["time_limit"] * (1 - full["operon_share"])}
    return {"backend": backend}
