"""Scene S8: work against precision of a sweep's bridge fidelities — the FE bridge time-stepped
(Newmark) at several meshes and Δt, the modal bridge time-stepped (Newmark, ``bridge=
'modal-stepped'``) and its exact passages at several meshes and Δt / sampling steps — on the S4
span and on the S5 viaduct.

Quantity: the sweep's envelope maximum of the deck acceleration counted up to the EN cut-off
(max over every deck node, every HSLM-A train and speed; `Output(..., cutoff='en')`), the
quantity the design check limits. Trains: HSLM-A1 … A10 as moving forces; speeds 140–420 km/h in
10 km/h steps (290 passages; ``--quick``: A1 and A4 at 5 speeds). Damping 1.3 % (S4) and 1.0 %
(viaduct): Rayleigh through n₀ and the cut-off for the FE bridge, the same ratio on every mode
for the modal bridge (on modes 1 and the cut-off mode the two are equal).

Reference: the modal bridge's exact passages on a fine mesh (40 elements per span) sampled every
0.1 ms. Cost: wall clock of ``Sweep.run(None, workers=1)`` per passage, after a warm-up (best of
``repeats``). Error: |max − reference| / reference.
"""
import os
import time

import numpy as np

from scenes import Scene, register

L4, F4, MU4 = 20.0, 5.0, 15000.0
VIADUCT = dict(spans=[30.0, 30.0, 30.0], E=3.5e10, I=7.0, mu=30000.0)
FE = [(n, dt) for n in (4, 8, 16) for dt in (4e-3, 2e-3, 1e-3, 5e-4)]
MODAL = [(n, dt) for n in (4, 10) for dt in (4e-3, 2e-3, 1e-3, 5e-4)]
METHOD_BRIDGE = {"FE Newmark": "fe", "modal Newmark": "modal-stepped", "modal exact": "modal"}


def _bridges():
    from vtsi.sweep import beam_bridge
    EI = MU4 * (2 * np.pi * F4 * (L4 / np.pi) ** 2) ** 2
    return {"S4 span (20 m)": (lambda n: beam_bridge([L4], EI, 1.0, MU4, n), 0.013),
            "S5 viaduct (3 x 30 m)": (lambda n: beam_bridge(VIADUCT["spans"], VIADUCT["E"], VIADUCT["I"],
                                                            VIADUCT["mu"], n), 0.010)}


def _max(build, n, trains, speeds, settings, repeats):
    from vtsi.passage import Output
    from vtsi.sweep import Sweep
    sweep = Sweep(build(n), trains, speeds, settings, [Output("acceleration", "accel", cutoff="en")])
    sweep.run(None, workers=1, progress=False, cases_per_task=len(sweep.cases))
    best = np.inf
    for _ in range(repeats):
        clock = time.perf_counter()
        res = sweep.run(None, workers=1, progress=False)
        best = min(best, time.perf_counter() - clock)
    return float(np.nanmax(res.envelope("acceleration_absmax"))), best / len(sweep.cases), len(sweep.cases)


def chart_work_precision(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    bridges = list(result["bridges"])
    fig, axes = plt.subplots(1, len(bridges), figsize=(6.2 * len(bridges), 4.6))
    for ax, name in zip(np.atleast_1d(axes), bridges):
        rows = result["bridges"][name]["rows"]
        for method, marker in (("FE Newmark", "o"), ("modal Newmark", "^"), ("modal exact", "s")):
            for n in sorted({r["elements"] for r in rows if r["method"] == method}):
                pts = sorted((r["ms_per_passage"], max(r["rel_err"], 1e-7), r["dt"]) for r in rows
                             if r["method"] == method and r["elements"] == n)
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=marker, lw=1.2,
                          label=f"{method}, {n} el/span")
                for x, y, dt in pts:
                    ax.annotate(f"{dt * 1e3:g}", (x, y), textcoords="offset points", xytext=(4, 3), fontsize=7)
        ax.axhline(5e-3, color="k", ls="--", lw=0.8, label="0.5 %")
        ax.set_xlabel("cost per passage [ms] (one core)")
        ax.set_ylabel("error of the envelope maximum [-]")
        ax.set_title(name, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Sweep fidelities: EN-filtered deck acceleration envelope, HSLM-A (labels: Δt in ms)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


@register
class S8(Scene):
    name = "S8"
    description = "work against precision of the sweep's fidelities: FE Newmark (meshes, dt), modal Newmark and exact modal passages, S4 span and S5 viaduct"
    columns = (("bridge", "bridge", "{}"), ("method", "method", "{}"), ("elements", "el/span", "{:d}"),
               ("dt", "dt [s]", "{:g}"), ("ms_per_passage", "ms/passage", "{:.3f}"), ("rel_err", "error", "{:.2e}"))

    def run(self, quick=False, baseline=False, repeats=3, chart=None):
        from vtsi.passage import PassageSettings
        trains = ["HSLM-A1", "HSLM-A4"] if quick else [f"HSLM-A{i}" for i in range(1, 11)]
        speeds = "300:380:20" if quick else "140:420:10"
        fe_grid, modal_grid = (FE[:2], MODAL[:2]) if quick else (FE, MODAL)
        out = {"scene": "S8", "quick": quick, "bridges": {}, "cases": []}
        for name, (build, zeta) in _bridges().items():
            ref, ref_cost, n_passages = _max(build, 40, trains, speeds,
                                             PassageSettings(dt=1e-4, damping=zeta, bridge="modal"), 1)
            rows = []
            for method, grid in (("FE Newmark", fe_grid), ("modal Newmark", modal_grid), ("modal exact", modal_grid)):
                for n, dt in grid:
                    settings = PassageSettings(dt=dt, damping=zeta, bridge=METHOD_BRIDGE[method])
                    value, cost, _ = _max(build, n, trains, speeds, settings, repeats)
                    rows.append({"bridge": name, "method": method, "elements": n, "dt": dt,
                                 "ms_per_passage": cost * 1e3, "max_acc": value, "rel_err": abs(value / ref - 1.0)})
            out["bridges"][name] = {"reference_max_acc": ref, "passages": n_passages, "rows": rows}
            out["cases"].extend(rows)
        fe_rows = [r for r in out["cases"] if r["method"] == "FE Newmark"]
        out["steps"] = None
        out["vtsi_s"] = sum(r["ms_per_passage"] for r in out["cases"]) * 1e-3
        out["vtsi_us_per_step"] = None
        out["peer"], out["peer_s"], out["peer_us_per_step"] = "exact modal reference (40 el/span, 0.1 ms)", None, None
        out["speedup"] = None
        out["max_rel_diff"] = min(r["rel_err"] for r in fe_rows)
        if chart is not None:
            out["chart"] = chart_work_precision(out, os.path.join(chart, "s8_work_precision.png"))
        return out
