"""satmd explain: use case III for a trained inverse model (figures + markdown summary)."""
from __future__ import annotations

from pathlib import Path

from ..errors import SatmdError
from ._common import Progress, check_outputs, dumps_json, integer

BACKENDS = ("hybrid", "operon", "skeleton", "pysr", "sindy")


MAX_THREADS = 256  # more threads than any machine's cores only wait on each other (and 1e6 aborts)


def register(sub):
    p = sub.add_parser("explain", help="explain a trained inverse net: attribution, latent, symbolic distillation",
                       description="Use case III for a model saved by `satmd inverse train`: neural attribution on "
                                   "the six blind pairs (Table 3) against the physical sensitivity ∂A/∂R, ∂A/∂L, "
                                   "the latent PCA with the R/L disentanglement test, and symbolic distillation "
                                   "of ξ_FRF and of modal descriptors. Writes figures, summary.md and "
                                   "explain.json.")
    p.add_argument("model", metavar="MODELDIR", help="folder written by `satmd inverse train`")
    p.add_argument("--out", default=None, metavar="DIR", help="output folder (default MODELDIR/explain)")
    p.add_argument("--backend", default="hybrid", choices=BACKENDS,
                   help="symbolic-regression backend (default hybrid: operon pooled with the skeleton pass; "
                        "pysr needs a Julia runtime)")
    p.add_argument("--threads", type=integer(1, MAX_THREADS), default=1, metavar="N",
                   help=f"threads for the symbolic search, 1..{MAX_THREADS} (default 1)")
    p.add_argument("--quick", action="store_true", help="smaller latent set and shorter symbolic searches")
    p.add_argument("--no-distill", action="store_true", help="skip the symbolic distillation")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.set_defaults(func=run)


def load_model(path):
    try:
        from ..inverse import InverseModel
    except ImportError as exc:
        raise SatmdError(f"satmd explain needs the inverse package and torch ({exc})") from None
    return InverseModel.load(path)


def run(args):
    model_dir = Path(args.model)
    if not model_dir.is_dir():
        raise SatmdError(f"{model_dir}: no such model folder")
    out = Path(args.out) if args.out else model_dir / "explain"
    check_outputs([("--out", out, None)])
    if args.backend == "pysr":
        from ..explain.backends import julia_runtime

        if julia_runtime() is None:  # refuse before any work is done
            raise SatmdError("the pysr backend needs a Julia runtime (julia not found on PATH); use --backend operon")
    model = load_model(model_dir)
    from ..explain.contract import check_net_model

    check_net_model(model)
    from ..report.explain_text import explain_model
    from ..io.atomic import all_or_none, atomic_write
    from ..plots import save

    fig_dir = out / "figures"
    written = []
    progress = Progress("explain", quiet=args.quiet)
    progress.step(f"attribution, latent and sensitivity of {model_dir}"
                  + ("" if args.no_distill else f", then symbolic distillation ({args.backend})")
                  + ("" if args.quick else "; about a minute or more (--quick for less)"), force=True)

    def figure(fig, name):
        written.append(save(fig, fig_dir / name))
        progress.step(f"{len(written)} figure(s) drawn, last {name}", force=True)
        return f"![{name}](figures/{name})"

    with all_or_none():  # figures, summary and JSON appear together or not at all
        md, results = explain_model(model, figure, backend=args.backend, quick=args.quick,
                                    symbolic=not args.no_distill, n_threads=args.threads)
        out.mkdir(parents=True, exist_ok=True)
        head = [f"# satmd explain: {model_dir}", "",
                f"Model kind `{model.kind}`, {len(model.networks_)} network(s), grid of {len(model.freq_hz)} "
                f"frequencies.", ""]
        with atomic_write(out / "summary.md", "w") as fh:
            fh.write("\n".join(head) + md + "\n")
        with atomic_write(out / "explain.json", "w") as fh:
            fh.write(dumps_json(results, "explain", indent=1, default=_json_default))

    def peaks(t):
        return "/".join(f"{p:.0f}" for p in sorted(t["R"]["peaks_hz"]))

    t3, t3s = results["neural"]["table3"], results["neural"]["table3_scaled"]
    line = (f"explain: Table 3 mean S_R/S_L {t3['R']['mean']:.3f}/{t3['L']['mean']:.3f} (raw features), "
            f"{t3s['R']['mean']:.3f}/{t3s['L']['mean']:.3f} (scaled; paper 0.305/0.342); S_R peaks "
            f"{peaks(t3)} Hz (raw), {peaks(t3s)} Hz (scaled)")
    if "symbolic" in results:
        xi = results["symbolic"]["xi"]
        line += f"; ξ formula {xi['complexity']} nodes, test R² {xi['r2_test']:.3f}"
    print(line)
    print(f"wrote {out / 'summary.md'}, {out / 'explain.json'} and {len(written)} figures in {fig_dir}")
    return 0


def _json_default(x):
    import numpy as np

    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return str(x)
