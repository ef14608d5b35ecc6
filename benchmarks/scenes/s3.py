"""Scene S3: the paper's 4-dof car over a 30 m simply supported span, accuracy against cost.

Model (models/scenes.py, ``S3``): a 30 m span (E = 3.5e10 Pa, I = 7 m⁴, 30 t/m, 20 Hermite
elements, f₁ ≈ 5.0 Hz, no damping) and a 4-dof car (body bounce and pitch over two wheel groups
of an ICE3 coach, l_c = 17.375 m, static wheel load P = 304.1 kN); smooth rail; the leading
wheel starts ``APPROACH`` = 2 m before the span, the car on rigid ground in its dead-load
equilibrium, and the run ends ``RUN_OUT`` = 50 ms after the rear wheel has left the span
(rounded up to a multiple of 4 ms so that every Δt samples the same instants).

Methods: Newmark (average acceleration, 'hermite' constraint rows), HHT with α = 0.9 (OpenSees
convention, ρ∞ = 0.82), Bathe (γ = 1/2, ρ∞ = 0, two stages per step), Newmark with the
'bspline' constraint (remedy (a), docs/theory/constraints.md §4), and Newmark with 'hermite'
rows and ``exact_events=True`` (each span entry and exit taken at its own time,
docs/theory/coupled_step.md §6).

(i) Work-precision, at 300 km/h, Δt = 4 ms … 0.125 ms, against the reference R1
    (``vtsi.reference.elimination.solve``, constraint elimination integrated by DOP853,
    rtol 1e-10, sampled every 0.125 ms; if R1 is not importable: Bathe at Δt = 0.125/16 ms):

    - contact force error = RMS over the wheels and the samples of the crossing (first entry to
      last exit) of (λ − λ_ref) / P, without the samples within ±5 ms of a wheel's entry or exit
      (where the exact bilateral λ holds an impulse, docs/theory/constraints.md §5; a
      time-stepping scheme spreads it over a step as a spike of impulse/Δt);
    - deflection error = max |w − w_ref| / max |w_ref| of the midspan deflection, whole run;
    - cost = CPU time (``time.process_time``) of ``CoupledAnalysis.run(n)`` from the dead-load
      state, the analysis already compiled and factored by a warm-up run; best of ``repeats``
      repetitions, each the mean over as many runs as last ``MIN_TIMED`` = 20 ms (runs at
      coarse Δt take about a millisecond).

(ii) Stability map, speed 100 … 400 km/h × Δt = 0.25 … 4 ms, each method: the ringing
    amplitude = max over the wheels and the crossing of |λ − λ̄| / P, λ̄ the moving average of λ
    over ≈ 10 ms (trapezoidal weights over 2m + 1 samples, m = max(1, round(5 ms / Δt)): a
    period-2Δt oscillation averages to zero exactly), without the samples within
    5 ms + mΔt of an entry or exit (so that λ̄ does not see the impulse either). A method
    *fails* at a cell when the ringing exceeds ``FAIL`` = 5 % of P or the run diverges.

JSON: the contract's fields, with vtsi = Newmark 'hermite' at 1 ms (the headline) and the peer =
the reference solver R1 (its wall time, ``speedup`` = R1 / vtsi, ``max_rel_diff`` = vtsi's
deflection error against R1); ``work_precision`` (one row per method and Δt, also in
``cases``), ``stability`` (the grids), ``charts`` (the PNG paths, with ``--chart DIR``).
"""
import math
import os
import time

import numpy as np

from scenes import Scene, register

SPEED_KMH = 300.0
DTS = (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4)
QUICK_DTS = (4e-3, 2e-3, 1e-3)
MAP_SPEEDS_KMH = (100.0, 150.0, 200.0, 250.0, 300.0, 350.0, 400.0)
MAP_DTS = (4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4)
QUICK_MAP_SPEEDS_KMH = (150.0, 300.0)
QUICK_MAP_DTS = (2e-3, 5e-4)
HEADLINE_DT = 1e-3
APPROACH = 2.0        # [m] leading wheel before the span at t = 0
RUN_OUT = 0.05        # [s] after the rear wheel has left the span
GRID = 4e-3           # the run's end is a multiple of this (every Δt divides it)
EXCLUDE = 5e-3        # [s] around each wheel's entry and exit
AVERAGE = 10e-3       # [s] moving-average window of the ringing metric
SMOOTH = 8e-3         # [s] averaging window of the smoothed contact-force error (a multiple of 2 Δt)
FAIL = 0.05           # ringing / static wheel load above which a method fails
R1_RTOL = 1e-10
CLOCK = time.process_time
MIN_TIMED = 0.02      # [s] a timed repetition runs the analysis as often as it takes to last this long
METHODS = ("Newmark", "HHT(0.9)", "Bathe", "Newmark+bspline", "Newmark+events")


def integrator_of(method):
    """(integrator, interpolation, exact_events) of a method name of :data:`METHODS`."""
    from vtsi.integrators import HHT

    return {"Newmark": ("Newmark", "hermite", False), "HHT(0.9)": (HHT(0.9), "hermite", False),
            "Bathe": ("Bathe", "hermite", False), "Newmark+bspline": ("Newmark", "bspline", False),
            "Newmark+events": ("Newmark", "hermite", True)}[method]


def build(speed_kmh, interpolation="hermite"):
    """The S3 model at ``speed_kmh``: ``(model, bridge, train, constraint)``."""
    import vtsi
    from vtsi.constraint import MovingLoadConstraint
    from vtsi.models.scenes import s3_model
    from vtsi.track import Track
    from vtsi.train import TrainSubdomain

    model = vtsi.Model()
    bridge, train, x_head0 = s3_model(model, speed=speed_kmh / 3.6, approach=APPROACH)
    constraint = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(train, x_head0),
                                      None, interpolation)
    return model, bridge, train, constraint


def scene_times(speed_kmh):
    """``(t_end, events, crossing)``: end time (multiple of :data:`GRID`), the entry and exit
    instants of every wheel, and (first entry, last exit) [s]."""
    from vtsi.models.scenes import S3

    V = speed_kmh / 3.6
    offsets = np.array([0.0, S3["l_c"]])
    entry = (APPROACH + offsets) / V
    exit_ = (APPROACH + S3["L"] + offsets) / V
    t_end = math.ceil((exit_[-1] + RUN_OUT) / GRID - 1e-9) * GRID
    return t_end, np.concatenate([entry, exit_]), (entry.min(), exit_.max())


class Runner:
    """A warmed-up coupled analysis of S3 that can be re-run from the dead-load state."""

    def __init__(self, method, speed_kmh, dt):
        from vtsi.coupled import CoupledAnalysis

        integrator, interpolation, exact_events = integrator_of(method)
        self.model, self.bridge, self.train, self.constraint = build(speed_kmh, interpolation)
        self.analysis = CoupledAnalysis(self.model, self.constraint, integrator, dt=dt, exact_events=exact_events)
        self.t_end = scene_times(speed_kmh)[0]
        self.n_steps = int(round(self.t_end / dt))
        self.static_load = float(self.train.static_wheel_loads[0])

    def warm_up(self):
        self.run(1)
        return self

    def run(self, n_steps=None):
        """``(cpu seconds, t, λ (n, 2), midspan uy (n,))``; raises DivergenceError."""
        from vtsi import domain_state
        from vtsi.recorders import NodeRecorder

        a = self.analysis
        domain_state(self.model).time = 0.0
        a.reset_records()
        rec = NodeRecorder([self.bridge.midspan_nodes[0]], [2], "disp")
        a.recorders = [rec]
        a.static()
        t0 = CLOCK()
        a.run(self.n_steps if n_steps is None else n_steps)
        seconds = CLOCK() - t0
        return seconds, a.time.copy(), a.contact_force.copy(), np.asarray(rec.values)[:, 0].copy()


# -- reference --------------------------------------------------------------------------------
def reference(speed_kmh, dt_out, kind="R1"):
    """λ and midspan deflection at ``t_k = k dt_out``, k = 1 … n: from R1 (``kind='R1'``) or from
    Bathe at ``dt_out / 16`` (``kind='bathe'``, also the fallback when R1 is not importable).

    Returns a dict with ``t``, ``force`` (n, 2), ``w`` (n,), ``kind``, ``seconds`` (wall time)."""
    t_end = scene_times(speed_kmh)[0]
    n = int(round(t_end / dt_out))
    t_eval = dt_out * np.arange(n + 1)
    t0 = time.perf_counter()
    solve = None
    if kind == "R1":
        try:
            from vtsi.reference.elimination import solve
        except ImportError:
            solve = None
    if solve is not None:
        model, bridge, _, constraint = build(speed_kmh, "hermite")
        sol = solve(model, constraint, t_end, t_eval, rtol=R1_RTOL)
        w = sol.node(bridge.midspan_nodes[0], 2)
        out = {"t": t_eval[1:], "force": sol.contact_force[1:], "w": w[1:],
               "kind": f"R1 (constraint elimination, DOP853, rtol {R1_RTOL:g})"}
    else:
        sub = 16
        run = Runner("Bathe", speed_kmh, dt_out / sub)
        _, t, force, w = run.run()
        out = {"t": t[sub - 1::sub], "force": force[sub - 1::sub], "w": w[sub - 1::sub],
               "kind": f"Bathe at dt = {1e3 * dt_out / sub:.4g} ms" + (" (R1 not importable)" if kind == "R1" else "")}
    out["seconds"] = time.perf_counter() - t0
    return out


# -- metrics ----------------------------------------------------------------------------------
def event_mask(t, events, crossing, margin):
    """Samples inside the crossing and farther than ``margin`` from every event."""
    keep = (t >= crossing[0]) & (t <= crossing[1])
    for e in events:
        keep &= np.abs(t - e) > margin
    return keep


def force_error(t, force, ref_force, events, crossing, static_load):
    """RMS over the kept samples and the wheels of (λ − λ_ref) / P."""
    keep = event_mask(t, events, crossing, EXCLUDE)
    d = (force[keep] - ref_force[keep]) / static_load
    return float(np.sqrt(np.mean(d * d)))


def moving_average(values, dt, window):
    """Average over ``window`` [s] (trapezoidal weights over 2m + 1 samples, m = window / (2 dt),
    at least 1), column by column; the first and last m rows are not valid."""
    m = max(1, int(round(0.5 * window / dt)))
    kernel = np.ones(2 * m + 1)
    kernel[0] = kernel[-1] = 0.5
    kernel /= kernel.sum()
    return np.column_stack([np.convolve(values[:, j], kernel, mode="same") for j in range(values.shape[1])]), m


def averaged_force_error(t, force, dt, ref_force_fine, dt_ref, events, crossing, static_load):
    """As :func:`force_error`, for λ and λ_ref both averaged over :data:`SMOOTH` (λ_ref on its
    fine grid, then sampled at the run's instants), without the samples within 5 ms + SMOOTH/2
    of an entry or exit."""
    mean, m = moving_average(force, dt, SMOOTH)
    ref_mean, _ = moving_average(ref_force_fine, dt_ref, SMOOTH)
    stride = int(round(dt / dt_ref))
    ref_mean = ref_mean[stride - 1::stride]
    keep = event_mask(t, events, crossing, EXCLUDE + 0.5 * SMOOTH)
    keep[:m] = False
    keep[len(t) - m:] = False
    d = (mean[keep] - ref_mean[keep]) / static_load
    return float(np.sqrt(np.mean(d * d)))


def deflection_error(w, ref_w):
    return float(np.max(np.abs(w - ref_w)) / np.max(np.abs(ref_w)))


def ringing(t, force, dt, events, crossing, static_load):
    """Max over the kept samples and the wheels of |λ − λ̄| / P (module docstring)."""
    mean, m = moving_average(force, dt, AVERAGE)
    keep = event_mask(t, events, crossing, EXCLUDE + m * dt)
    keep[:m] = False
    keep[len(t) - m:] = False
    if not keep.any():
        return 0.0
    return float(np.max(np.abs(force[keep] - mean[keep]))) / static_load


# -- the two studies --------------------------------------------------------------------------
def work_precision(dts, repeats, reference_kind="R1"):
    """Rows (method, Δt, errors, CPU time) at :data:`SPEED_KMH` against the reference, the
    reference, and the check of the reference: the errors of Bathe at min(Δt)/16 against it."""
    from vtsi.errors import DivergenceError

    ref = reference(SPEED_KMH, min(dts), reference_kind)
    _, events, crossing = scene_times(SPEED_KMH)
    check = None
    if ref["kind"].startswith("R1"):
        other = reference(SPEED_KMH, min(dts), "bathe")
        check = {"against": other["kind"],
                 "force_error": force_error(ref["t"], other["force"], ref["force"], events, crossing,
                                            Runner("Bathe", SPEED_KMH, min(dts)).static_load),
                 "deflection_error": deflection_error(other["w"], ref["w"])}
    rows = []
    for method in METHODS:
        for dt in dts:
            runner = Runner(method, SPEED_KMH, dt).warm_up()
            stride = int(round(dt / min(dts)))
            best, diverged, inner = math.inf, False, 1
            for _ in range(repeats):
                try:
                    seconds = 0.0
                    for _ in range(inner):          # short runs: time several, keep their mean
                        s, t, force, w = runner.run()
                        seconds += s
                except DivergenceError:
                    diverged = True
                    break
                best = min(best, seconds / inner)
                inner = max(inner, int(math.ceil(MIN_TIMED / max(best, 1e-6))))
            row = {"method": method, "dt": dt, "steps": runner.n_steps, "stages": 2 if method == "Bathe" else 1}
            if diverged:
                row["diverged"] = True               # no error or time fields (the table prints –)
            else:
                r_t, r_f, r_w = ref["t"][stride - 1::stride], ref["force"][stride - 1::stride], ref["w"][stride - 1::stride]
                if len(r_t) != len(t) or np.max(np.abs(r_t - t)) > 1e-9:
                    raise RuntimeError(f"S3: the reference samples do not match the {method} run at dt = {dt}")
                row.update(diverged=False,
                           force_error=force_error(t, force, r_f, events, crossing, runner.static_load),
                           force_error_smoothed=averaged_force_error(t, force, dt, ref["force"], min(dts), events,
                                                                     crossing, runner.static_load),
                           deflection_error=deflection_error(w, r_w),
                           cpu_s=best, us_per_step=1e6 * best / runner.n_steps)
            rows.append(row)
    return rows, ref, check


def stability_map(speeds, dts):
    """Ringing amplitude per method over speed × Δt; ``None`` where the run diverged."""
    from vtsi.errors import DivergenceError

    grids = {}
    for method in METHODS:
        grid = []
        for dt in dts:
            line = []
            for v in speeds:
                _, events, crossing = scene_times(v)
                runner = Runner(method, v, dt)
                try:
                    _, t, force, _ = runner.run()
                except DivergenceError:
                    line.append(None)
                    continue
                line.append(ringing(t, force, dt, events, crossing, runner.static_load)
                            if np.all(np.isfinite(force)) else None)
            grid.append(line)
        grids[method] = grid
    failed = {m: [[g is None or g > FAIL for g in line] for line in grid] for m, grid in grids.items()}
    return {"speeds_kmh": list(speeds), "dts": list(dts), "methods": list(METHODS), "ringing": grids,
            "failed": failed, "fail_threshold": FAIL,
            "metric": "max over the crossing of |lambda - moving average (10 ms)| / static wheel load; "
                      "null = diverged"}


# -- charts -----------------------------------------------------------------------------------
COLORS = {"Newmark": "tab:red", "HHT(0.9)": "tab:orange", "Bathe": "tab:blue", "Newmark+bspline": "tab:green",
          "Newmark+events": "tab:purple"}
MARKERS = {"Newmark": "o", "HHT(0.9)": "s", "Bathe": "D", "Newmark+bspline": "^", "Newmark+events": "v"}
LABELS = {"Newmark": "Newmark (Hermite rows)", "HHT(0.9)": "HHT α = 0.9 (Hermite rows)",
          "Bathe": "Bathe γ = 1/2 (Hermite rows)", "Newmark+bspline": "Newmark + B-spline rows",
          "Newmark+events": "Newmark, span ends at their time"}


def chart_work_precision(rows, ref, path, repeats=3):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.8), constrained_layout=True)
    panels = ((axes[0], "force_error", "contact force λ: RMS(λ − λ_ref) / P\nover the crossing, ±5 ms around entries/exits left out"),
              (axes[1], "force_error_smoothed", f"λ averaged over {1e3 * SMOOTH:g} ms: RMS(λ̄ − λ̄_ref) / P\n"
                                                f"(±{1e3 * (EXCLUDE + SMOOTH / 2):g} ms around entries/exits left out)"),
              (axes[2], "deflection_error", "midspan deflection w:\nmax|w − w_ref| / max|w_ref| over the run"))
    for ax, key, title in panels:
        for method in METHODS:
            pts = [r for r in rows if r["method"] == method and not r["diverged"]]
            if not pts:
                continue
            x = [1e3 * r["cpu_s"] for r in pts]
            y = [r[key] for r in pts]
            ax.loglog(x, y, marker=MARKERS[method], color=COLORS[method], label=LABELS[method], lw=1.3, ms=5)
            if method in ("Bathe", "Newmark"):
                for r, xi, yi in zip(pts, x, y):
                    ax.annotate(f"{1e3 * r['dt']:g}", (xi, yi), textcoords="offset points",
                                xytext=(4, 4 if method == "Bathe" else -10), fontsize=7, color=COLORS[method])
        ax.set_xlabel(f"CPU time per run [ms] (best of {repeats})")
        ax.set_ylabel("relative error")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].axhline(FAIL, color="grey", ls=":", lw=1)
    axes[0].text(axes[0].get_xlim()[0] * 1.05, FAIL * 1.15, "5 % of P", fontsize=7, color="grey")
    axes[0].legend(fontsize=8, loc="center right")
    fig.suptitle(f"S3 work-precision: 4-dof car over a 30 m span at {SPEED_KMH:g} km/h, Δt = "
                 f"{1e3 * max(r['dt'] for r in rows):g} … {1e3 * min(r['dt'] for r in rows):g} ms "
                 f"(labels: Δt in ms); reference: {ref['kind'].split(' (')[0]}", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def chart_stability(stab, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Rectangle

    speeds, dts = stab["speeds_kmh"], stab["dts"]
    values = [v for g in stab["ringing"].values() for line in g for v in line if v is not None and v > 0]
    lo = max(min(values), 1e-5) if values else 1e-4
    hi = max(max(values), 10 * FAIL) if values else 1.0
    norm = LogNorm(vmin=lo, vmax=hi)
    fig, axes = plt.subplots(2, 3, figsize=(15, 7.6), constrained_layout=True, sharex=True, sharey=True)
    for ax in axes.ravel()[len(stab["methods"]):]:
        ax.set_visible(False)
    image = None
    for ax, method in zip(axes.ravel(), stab["methods"]):
        grid = np.array([[np.nan if v is None else max(v, lo) for v in line] for line in stab["ringing"][method]])
        image = ax.imshow(grid, norm=norm, cmap="viridis", origin="lower", aspect="auto",
                          extent=(-0.5, len(speeds) - 0.5, -0.5, len(dts) - 0.5))
        for i, line in enumerate(stab["ringing"][method]):
            for j, v in enumerate(line):
                if v is None:
                    ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, facecolor="0.6", edgecolor="k", hatch="xx", lw=0.5))
                    ax.text(j, i, "div.", ha="center", va="center", fontsize=7)
                    continue
                if v > FAIL:
                    ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, edgecolor="w", hatch="///", lw=0.0))
                dark = norm(max(v, lo)) < 0.6
                ax.text(j, i, f"{100 * v:.0f}" if v >= 0.1 else f"{100 * v:.2g}", ha="center", va="center", fontsize=7,
                        color="w" if dark else "k")
        n_fail = sum(v is None or v > FAIL for line in stab["ringing"][method] for v in line)
        ax.set_title(f"{LABELS[method]}: fails in {n_fail} of {len(speeds) * len(dts)} cells", fontsize=9)
        ax.set_xticks(range(len(speeds)), [f"{v:g}" for v in speeds])
        ax.set_yticks(range(len(dts)), [f"{1e3 * d:g}" for d in dts])
    for col in range(axes.shape[1]):     # the lowest visible panel of each column carries the speeds
        ax = axes[1, col] if axes[1, col].get_visible() else axes[0, col]
        ax.tick_params(labelbottom=True)
        ax.set_xlabel("train speed [km/h]")
    for ax in axes[:, 0]:
        ax.set_ylabel("Δt [ms]")
    bar = fig.colorbar(image, ax=axes, shrink=0.9, label="ringing: max |λ − λ̄₁₀ₘₛ| / P (log scale)")
    bar.ax.axhline(FAIL, color="w", lw=2)
    bar.ax.text(0.5, FAIL, "5 %\nfails", color="w", ha="center", va="bottom", fontsize=7, transform=bar.ax.get_yaxis_transform())
    fig.suptitle(f"S3 stability map: ringing of the contact force (numbers in % of the static wheel load P; "
                 f"hatched: > {100 * FAIL:g} % = fails; grey 'div.': diverged)", fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)


@register
class S3(Scene):
    name = "S3"
    description = ("4-dof car over a 30 m simply supported span: work-precision against the reference R1 and "
                   "a ringing map over speed x dt for Newmark, HHT(0.9), Bathe, Newmark+B-spline")
    columns = (
        ("method", "method", "{}"),
        ("dt", "dt [s]", "{:.4g}"),
        ("steps", "steps", "{:d}"),
        ("us_per_step", "µs/step", "{:.2f}"),
        ("cpu_s", "CPU s/run", "{:.4f}"),
        ("force_error", "λ error", "{:.2e}"),
        ("force_error_smoothed", "λ̄ error", "{:.2e}"),
        ("deflection_error", "w error", "{:.2e}"),
    )

    def run(self, quick=False, baseline=False, repeats=3, chart=None, reference_kind=None):
        t_start = time.perf_counter()
        dts = QUICK_DTS if quick else DTS
        reference_kind = reference_kind or os.environ.get("VTSI_S3_REFERENCE", "R1")
        rows, ref, check = work_precision(dts, repeats, reference_kind)
        stab = stability_map(QUICK_MAP_SPEEDS_KMH if quick else MAP_SPEEDS_KMH, QUICK_MAP_DTS if quick else MAP_DTS)
        head = next(r for r in rows if r["method"] == "Newmark" and abs(r["dt"] - HEADLINE_DT) < 1e-12)
        result = {
            "scene": self.name, "description": self.description,
            "headline": f"Newmark 'hermite' at dt = {HEADLINE_DT:g} s, {SPEED_KMH:g} km/h; peer = the reference solver",
            "speed_kmh": SPEED_KMH, "steps": head["steps"], "dt": HEADLINE_DT,
            "vtsi_s": head["cpu_s"], "vtsi_us_per_step": head["us_per_step"],
            "peer": "R1 reference" if ref["kind"].startswith("R1") else "Bathe dt/16 reference",
            "peer_s": ref["seconds"], "peer_us_per_step": 1e6 * ref["seconds"] / head["steps"],
            "speedup": ref["seconds"] / head["cpu_s"] if head["cpu_s"] else None,
            "max_rel_diff": head["deflection_error"],
            "reference": ref["kind"], "reference_s": ref["seconds"], "reference_check": check,
            "force_error_exclusion_s": EXCLUDE,
            "work_precision": rows, "cases": rows, "stability": stab,
            "us_per_step": {m: {f"{r['dt']:g}": r["us_per_step"] for r in rows if r["method"] == m} for m in METHODS},
            "repeats": repeats, "quick": quick, "clock": "process_time (CPU)",
        }
        charts = {}
        if chart is not None:
            charts["work_precision"] = os.path.abspath(os.path.join(chart, "s3_work_precision.png"))
            charts["stability_map"] = os.path.abspath(os.path.join(chart, "s3_stability_map.png"))
            chart_work_precision(rows, ref, charts["work_precision"], repeats)
            chart_stability(stab, charts["stability_map"])
        result["charts"] = charts
        result["total_s"] = time.perf_counter() - t_start
        return result
