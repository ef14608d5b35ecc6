"""The EN 1990 A2 / EN 1991-2 dynamic design check of a sweep's results (docs/check.md).

A check reads a sweep's results file and evaluates each criterion against its limit; it runs no
analysis. The rules and limits come from :mod:`vtsi.codes` (one place, with their clauses); what
each row means:

=====================  ===========================================================  ==========
criterion              value                                                        clause
=====================  ===========================================================  ==========
deck_acceleration      max |a| of the deck, frequencies up to max(30 Hz, 1.5 n₀,    EN 1990
                       n₃) (an output with ``cutoff='en'``; of several decks the     A2.4.4.2.1
                       largest of their cut-offs), ≤ 3.5 m/s² ballasted, 5 m/s²
                       direct fastening
dynamic_increment      φ'_dyn = max |y_dyn / y_stat| − 1 of the deflection of each   EN 1991-2
                       span's middle, y_stat the static deflection under the same    6.4.6.5(3)
                       train (info); ``_moment``: the same for the mid-span
                       bending moment (sagging); ``_support_moment``: for the
                       hogging moment over a continuous deck's intermediate
                       supports (none on simply supported decks)
dynamic_vs_lm71        (1 + φ'_dyn + φ''/2) y_stat,train / (Φ α y_stat,LM71/SW/0),   EN 1991-2
                       the largest over trains and spans (or supports): > 1 means    6.4.6.5(3),
                       the dynamic analysis, not Φ × LM71/SW/0, governs the design   6.3.3,
                       (info); ``_moment``, ``_support_moment`` as above             Annex C
deflection             the more unfavourable of Φ α × LM71/SW/0's static             EN 1990
                       deflection and (1 + φ'_dyn + φ''/2) × each train's, i.e.      A2.4.4.2.3(1),
                       max |y_dyn| + φ''/2 × |y_stat,train| (φ'' whole for standard  EN 1991-2
                       maintenance), ≤ L/600 per span (Φ, φ'' of the span's deck's   6.4.6.5(3)
                       L_Φ and n₀)
deflection_overhang    the same on a deck's overhang, against L_c/600 of its length  EN 1991-2
                       for reference only (info: EN 1990 gives no cantilever limit)  6.4.6.5(3)
end_rotation           max |θ| at the decks' end supports under the trains (info:   EN 1990
                       EN limits the deck end's displacement: not checked)           A2.4.4.2.3,
                                                                                     EN 1991-2
                                                                                     6.5.4.5.2
car_body_acceleration  max |a| of the car bodies, at each centre or over either      EN 1990
                       bogie pivot, while a wheel of the car is on a deck and half   A2.4.4.3.1
                       a period of its lowest mode after, ≤ b_v (Table A2.9)
wheel_unloading        max ΔQ/Q = 1 − λ_min / Q (Q the static wheel load, λ the      project
                       contact force's 10 ms mean, while the wheel is on a deck) ≤   criterion
                       the project's limit (0.6 by default: not an EN 1990 clause)
contact_loss           passages in which a wheel lifts on a deck (the mean λ ≤ 0)    —
                       = 0
=====================  ===========================================================  ==========

LM71/SW/0 is the static reference of EN 1991-2 6.4.6.5(3) (:func:`static_reference`): LM71's
static value, or on a continuous deck the more unfavourable of LM71's and SW/0's (6.3.3(1)P:
SW/0 loads continuous beams), both × α; the rows name which one they read. The moment rows read
the track elements' moment: where these carry less than :data:`LOCAL_MOMENT_SHARE` of their
span's free-body moment (a truss's chord, a stringer on cross girders: :func:`moment_shares`),
it is their own local bending, and the rows keep their values, not checked, with no reference.

The car rows judge what the bridge does: a sweep's vehicle envelopes count a wheel while it is on
a deck and a car body while a wheel of it is (:meth:`vtsi.passage.PassageRunner.counted`); where
the whole run (rigid ground with an irregular rail before and after the bridge) holds a larger
value, the row's note gives it with its case and place; a track end that sags under the trains'
heaviest wheel, a step for the wheels (:mod:`vtsi.track_ends`), is named in the wheel unloading
and contact loss rows' notes. Each row names the governing train,
speed, rail sample and place ('node 26 (x = 62.5 m, span 3)'; 'wheel 3 of 32 (car 1 of 8), x = 6.4 m'; 'car 2 of 8':
people's counting from 1, where the results file's indices count from 0; :mod:`vtsi.places`), with
the value, the limit and the utilisation value / limit; ``status`` is 'pass', 'fail' or 'info'
(no limit, or a value the check cannot hold to its limit: wheel unloading and contact loss from
Newmark's undamped rule with 'hermite' rows; 'info' rows carry their reading in ``note``). Rows
whose outputs the sweep did not keep are left out. Speeds that step across a resonance v = n D /
i more coarsely than the EN series (:func:`vtsi.speed_grid.coarse_resonances`), or that start
above the series' 144 km/h, or that step more coarsely than its 2 km/h over a train without D
(its resonances unknown), are named in the rows read against speed and in the verdict, and a
criterion with a limit that passes on them (deck acceleration, deflection, car-body acceleration,
wheel unloading, contact loss: each peaks at resonance) is not checked (info). A sweep holding an
HSLM train without every one EN 1991-2 6.4.6.1.1, Table 6.4 loads the bridge's decks with (all
ten HSLM-A on a continuous deck or a span of 7 m or more: vtsi does not make Annex E's choice of
a single critical one; HSLM-B on a simply supported span under 7 m) leaves the deck acceleration
and the deflection, read from the dynamic analysis under them, not checked (info) unless they
fail (:func:`_load_models`); a sweep of real trains only is a check for those trains.

The verdict (:meth:`CheckResult.verdict`) is FAIL when a criterion fails; else NO VERDICT when
the sweep is incomplete, when a criterion with a limit could not be held to it (an 'info' row
of the five above with a limit: not checked) or when none was held to a limit; else PASS.
"""
import datetime
import json
import math
import os
import shutil
from dataclasses import asdict, dataclass, field
from typing import NamedTuple

import h5py
import numpy as np

from vtsi.codes import en1990_a2, en1991_2
from vtsi.damping import deck_frequencies_table, rayleigh_coefficients, rayleigh_ratio
from vtsi.deck_record import deck_nodes, intermediate_supports, overhangs, span_columns, support_columns
from vtsi.errors import ModelError, SweepError, VtsiError
from vtsi.influence import InfluenceLines
from vtsi.integrators import make_integrator
from vtsi.modal_bridge import CUTOFF_MARGIN
from vtsi.model import Model
from vtsi.passage import (AXLE_PAIR_HARMONICS, STEPS_PER_CUTOFF_PERIOD, default_dt, default_modal_hz, dt_resolving,
                          en_cutoff_hz, modal_basis_hz, rail_frequency_hz, resolves, step_effect, step_error_text,
                          step_ratio, step_rule_text)
from vtsi.places import car_label, decks_text, node_text, wheel_or_car_place
from vtsi.speed_grid import UnknownResonances, coarse_resonances, coarse_text
from vtsi.sweep_results import (ENVELOPE_ROWS, ResultsFileLock, SweepResults, bridge_text, deck_first_frequencies,
                                significant_text, span_decks, x_tolerance)
from vtsi.track import Track
from vtsi.track_ends import TrackEnd, free_end_text

MIN, MAX, ABSMAX = (ENVELOPE_ROWS.index(k) for k in ("min", "max", "absmax"))
RENAMED = {"deflection_lm71": "deflection"}   # rows of checks stored by an older vtsi, by today's name
DIMENSIONLESS = "-"          # the units of a ratio (a row's, an output's): written as none
WITH_A_VERDICT = ("deck_acceleration", "deflection", "car_body_acceleration", "wheel_unloading", "contact_loss")
PEAK_AT_RESONANCE = ("deck_acceleration", "deflection", "dynamic_increment", "dynamic_vs_lm71", "car_body_acceleration",
                     "wheel_unloading", "contact_loss")   # the rows read against speed (prefixes): a speed grid's notes
STATIC_LOAD_MODELS = ("LM71", "SW/0")   # a deflection row's 'train' where Φ α × its static value governs
LOCAL_MOMENT_SHARE = 0.1
"""The least share of its span's free-body moment (:func:`moment_shares`) that the track
elements' mid-span moment reaches on a deck whose beam they are: below it they are a chord or a
stringer of a structure that carries the span's bending, and the moment rows, which read their
local bending, are not checked. Measured under LM71 (SW/0): a simply supported beam 1, the
middles of a 2 × 20 m beam 0.76 (0.76), of a 4 × 35 m beam 0.79 and 0.65, of an integral 12 m
portal frame 0.52; a beam clamped at both ends 0.35 to 0.37 (0.33 to 0.41) at 5 to 100 m, and
with haunches 8 times as stiff over its outer 15 % at each end 0.21 to 0.23 (0.19 to 0.26): the
least a beam deck reads; the bottom chord of a 40 m truss of 8 panels 0.021."""
SW0_MISSING = ("; the static reference is LM71 alone: the results file, of an older vtsi, holds no SW/0, which EN "
               "1991-2 6.3.3(1)P adds on a continuous deck (sweep again into a new file to read it)")


@dataclass(frozen=True)
class CheckSettings:
    """What the check needs beyond the results (all stored with the check).

    track : 'ballasted' or 'direct_fastening' (deck acceleration limit).
    comfort : 'very_good', 'good' or 'acceptable' (Table A2.9).
    maintenance : 'careful' (Φ₂, φ''/2) or 'standard' (Φ₃, φ'').
    alpha : classification factor α of LM71 [-].
    unloading_limit : ΔQ/Q limit [-] (a project criterion).
    damping_source : where the sweep's damping ratio came from, for the report's reader, e.g.
        'EN 1991-2 Table 6.6, steel, L = 20 m: 0.5 % + Eq. 6.13 Δζ 0.3 %' (``vtsi check``
        --bridge-type), '--damping' or "the bridge file's [analysis] damping"; '' not recorded.
    line_speed_kmh : the line's maximum speed [km/h] (EN 1991-2 6.4.6.2: the speeds up to 1.2 ×
        it); None not recorded.

    The last two are provenance only: no criterion's value reads them (the line speed sets where
    the speed grid is read from, :func:`vtsi.speed_grid.coarse_resonances`), and they are not part
    of the sweep's identity (a sweep resumes whatever they are).
    """

    track: str = "ballasted"
    comfort: str = "good"
    maintenance: str = "careful"
    alpha: float = 1.0
    unloading_limit: float = 0.6
    damping_source: str = ""
    line_speed_kmh: float = None

    def __post_init__(self):
        en1990_a2.deck_acceleration_limit(self.track)
        en1990_a2.comfort_limit(self.comfort)
        en1991_2.dynamic_factor(10.0, self.maintenance)
        if not isinstance(self.damping_source, str):
            raise ModelError(f"check settings: damping_source must be text, got {self.damping_source!r}")
        if self.line_speed_kmh is not None:
            value = self.line_speed_kmh
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
                and np.isfinite(value) and value > 0
            if not ok:
                raise ModelError(f"check settings: line_speed_kmh must be a speed > 0 [km/h] or None, got {value!r}")
            object.__setattr__(self, "line_speed_kmh", float(value))
        for name, most in (("alpha", np.inf), ("unloading_limit", 1.0)):
            value = getattr(self, name)
            ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
                and np.isfinite(value) and 0 < value <= most
            if not ok:
                raise ModelError(f"check settings: {name} must be a number > 0" + (f" and <= {most:g}" if most < np.inf
                                                                                   else "") + f", got {value!r}")
            object.__setattr__(self, name, float(value))


@dataclass
class CheckRow:
    """One criterion's outcome (see the module docstring)."""

    criterion: str
    clause: str
    value: float
    units: str
    limit: float = np.nan
    utilisation: float = np.nan
    status: str = "info"
    train: str = ""
    speed_kmh: float = np.nan
    seed: int = -1
    where: str = ""
    note: str = ""


@dataclass
class CheckResult:
    """The rows of a check, with its settings."""

    settings: CheckSettings
    rows: list = field(default_factory=list)
    cases_done: int = 0         # the sweep's finished cases when it was checked, of ...
    cases_total: int = 0        # ... its cases (0 and 0: not known, a check stored by an older vtsi)
    bridge: str = ""            # the bridge as the check read it (vtsi.sweep_results.bridge_text): one line
    speed_grid: str = ""        # the resonances the sweep's speeds step across more coarsely than the EN
                                # series, and the trains without D they step too coarsely for
                                # (:func:`vtsi.speed_grid.coarse_resonances`), one line; '' when none
    bridge_model: str = ""      # the sweep's bridge model, FE or modal and its basis (:func:`bridge_model_text`),
                                # one line; '' not known
    frequency_limits: str = ""  # each deck's n₀ against EN 1991-2 Figure 6.10 (:func:`frequency_limits_text`),
                                # one line of information; '' not known
    hslm_b: str = ""            # the sweep's HSLM-B from vtsi's unverified reading of EN 1991-2 Figure 6.13
                                # (:func:`hslm_b_text`), one sentence the verdict carries; '' when none

    @property
    def complete(self):
        """Whether the check read every case of its sweep."""
        return self.cases_done >= self.cases_total

    @property
    def passed(self):
        """True when the sweep is complete, a criterion with a limit was checked, none fails and
        none with a row was left not checked (:attr:`unchecked`); the criteria with no row
        (:attr:`not_evaluated`) do not count."""
        return (self.complete and any(r.status == "pass" for r in self.rows)
                and all(r.status != "fail" for r in self.rows) and not self.unchecked)

    @property
    def unchecked(self):
        """The criteria with a limit whose row the check could not hold to it (status info)."""
        return [r.criterion for r in self.rows if r.status == "info" and r.criterion in WITH_A_VERDICT]

    @property
    def not_evaluated(self):
        """The criteria with a limit that have no row: the sweep kept no output they read (a
        sweep of moving forces has no car body or contact force)."""
        present = {RENAMED.get(r.criterion, r.criterion) for r in self.rows}
        return [c for c in WITH_A_VERDICT if c not in present]

    def verdict(self, label=str):
        """One line: FAIL (how many of the criteria held to a limit fail, and which), NO VERDICT
        (an incomplete sweep; a criterion with a limit not checked, :attr:`unchecked`, named
        with how many of the others pass; or nothing held to a limit) or PASS, with what was not
        checked or not evaluated; ``label`` names a criterion (the report's words)."""
        failed = [label(r.criterion) for r in self.rows if r.status == "fail"]
        held = sum(r.status in ("pass", "fail") for r in self.rows)
        missing = f"{self.cases_done} of {self.cases_total} cases"
        unchecked = ", ".join(map(label, self.unchecked))
        if failed:
            text = (f"FAIL: {len(failed)} of {held} {'criterion' if held == 1 else 'criteria'} held to a limit "
                    f"fail{'s' if len(failed) == 1 else ''}: {', '.join(failed)}"
                    + ("" if self.complete else f" (in an incomplete sweep: {missing})"))
        elif not self.complete:
            text = f"NO VERDICT: the sweep is incomplete ({missing}; resume it, then check again)"
        elif self.unchecked:
            one = len(self.unchecked) == 1
            others = ("no other criterion was held to a limit" if not held else "the criterion checked passes"
                      if held == 1 else f"the {held} criteria checked pass")
            text = f"NO VERDICT: {unchecked} not checked (see {'its note' if one else 'their notes'}); {others}"
        elif self.passed:
            text = "PASS: every criterion checked is within its limit"
        else:
            text = "NO VERDICT: no criterion with a limit was checked"
        if self.unchecked and (failed or not self.complete):
            text += f" (not checked: {unchecked}; see {'its note' if len(self.unchecked) == 1 else 'their notes'})"
        if self.not_evaluated and not failed:
            text += f" (not evaluated, the sweep kept no output for them: {', '.join(map(label, self.not_evaluated))})"
        if self.speed_grid:
            text += f"; {self.speed_grid}"
        if self.hslm_b:
            text += f"; {self.hslm_b}"
        return text

    def settings_text(self):
        """The settings in one line, as the text table and the report state them: track, level of
        comfort and what of EN 1990 A2.4.4.3 was read against it (the car bodies' b_v, Table A2.9,
        where the check has their row; the deflection limits of A2.4.4.3.2, Figure A2.3, never),
        maintenance, α and, where the check read contact forces, the wheel unloading limit."""
        s, criteria = self.settings, {r.criterion for r in self.rows}
        body = ("the car bodies' b_v, Table A2.9" if "car_body_acceleration" in criteria else
                "not checked: the sweep kept no car body (moving forces have none) for Table A2.9's b_v")
        unloading = (f", wheel unloading limit ΔQ/Q = {s.unloading_limit:g} (a project criterion)"
                     if "wheel_unloading" in criteria else "")
        return (f"{s.track.replace('_', ' ')} track, comfort level '{s.comfort.replace('_', ' ')}' ({body}; the "
                f"deflection limits of EN 1990 A2.4.4.3.2, Figure A2.3, are not checked), {s.maintenance} maintenance, "
                f"α = {s.alpha:g}{unloading}")

    def row(self, criterion):
        """The row of ``criterion`` (SweepError naming the rows there are when it has none)."""
        for r in self.rows:
            if r.criterion == criterion:
                return r
        raise SweepError(f"check: no row {criterion!r}; the rows are {', '.join(r.criterion for r in self.rows)}")

    def text(self):
        """The bridge as the check read it (one line: its decks, spans, n₀, EN cut-off, L_Φ), the
        settings (one line, :meth:`settings_text`), the sweep's bridge model (one line, as the
        report's settings give it: :func:`bridge_model_text`), each deck's n₀ against EN 1991-2
        Figure 6.10 (one line, :func:`frequency_limits_text`), then the table (one line per
        criterion), the verdict and the rows' notes."""
        head = ("criterion", "value", "limit", "util.", "status", "governing case", "where", "clause")
        lines = [head]
        for r in self.rows:
            case = r.train + ("" if np.isnan(r.speed_kmh) else f" {r.speed_kmh:g} km/h")
            if r.train and r.seed >= 0:
                case += f" seed {r.seed}"
            held = r.status != "info"          # an info row's limit is a reference: no utilisation
            unheld = "" if held else ("not checked " if r.criterion in self.unchecked else "ref. ")   # as the report
            lines.append((r.criterion, "not evaluated" if np.isnan(r.value) else self.value_text(r, f"{r.value:.4g}"),
                          "" if np.isnan(r.limit) else f"{unheld}{r.limit:.4g}",
                          "" if np.isnan(r.utilisation) or not held else f"{r.utilisation:.2f}", r.status.upper(),
                          case, r.where, r.clause))
        widths = [max(len(line[j]) for line in lines) for j in range(len(head))]
        out = ["  ".join(c.ljust(w) for c, w in zip(line, widths)).rstrip() for line in lines]
        out.insert(1, "  ".join("-" * w for w in widths))
        notes = [f"  {r.criterion}: {r.note}" for r in self.rows if r.note]
        return "\n".join(([self.bridge] if self.bridge else []) + [f"check settings: {self.settings_text()}"]
                         + ([f"bridge model: {self.bridge_model}"] if self.bridge_model else [])
                         + ([self.frequency_limits] if self.frequency_limits else []) + out
                         + ["", self.verdict()]
                         + (["notes:"] + notes if notes else []))

    def value_text(self, row, number, units=str):
        """``number`` (the row's value as text) with its units (as ``units`` writes them), none
        after a ratio (units '-': '6.934', not '6.934 -', which reads as a minus sign); a count
        of passages as 'k of n passages', n the passages the check read."""
        if row.units == "passages" and self.cases_done:
            return f"{number} of {self.cases_done} passages"
        return number if row.units == DIMENSIONLESS else f"{number} {units(row.units)}".strip()

    def store(self, path):
        """Write the table into the sweep's results file (/checks: one row per criterion, the
        settings in its attributes), atomically as the sweep writes (copy, write, rename)."""
        path = os.fspath(path)
        SweepResults(path)                     # a readable results file of a sweep, or a SweepError naming it
        lock = ResultsFileLock(path)           # no sweep writes it meanwhile (a ResultsFileInUse naming it)
        tmp = path + ".partial"
        try:
            shutil.copyfile(path, tmp)
            with h5py.File(tmp, "a") as f:
                if "checks" in f:
                    del f["checks"]
                g = f.create_group("checks")
                g.attrs["settings"] = json.dumps(asdict(self.settings))
                g.attrs["created"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
                g.attrs["passed"] = self.passed
                g.attrs["cases_done"], g.attrs["cases_total"] = self.cases_done, self.cases_total
                g.attrs["speed_grid"] = self.speed_grid
                for name in CheckRow.__dataclass_fields__:
                    values = [getattr(r, name) for r in self.rows]
                    if values and isinstance(values[0], str):
                        g.create_dataset(name, data=np.array(values, dtype=h5py.string_dtype()))
                    else:
                        g.create_dataset(name, data=np.array(values, dtype=float if name != "seed" else np.int64))
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
            lock.release()


def stored_check(path):
    """The check stored in a results file (:meth:`CheckResult.store`), or None."""
    results = SweepResults(path)           # a readable results file of a sweep, or a SweepError naming it
    with h5py.File(results.path, "r") as f:
        if "checks" not in f:
            return None
        g = f["checks"]
        if "settings" not in g.attrs or "criterion" not in g:
            raise SweepError(f"results file {results.path}: its /checks is not a stored check (no settings or rows)")
        try:
            settings = CheckSettings(**json.loads(g.attrs["settings"]))
        except (ModelError, TypeError, ValueError) as exc:
            raise SweepError(f"results file {results.path}: the stored check's settings are not valid: {exc}") from None
        n = len(g["criterion"])
        rows = []
        for i in range(n):
            values = {}
            for name in CheckRow.__dataclass_fields__:
                v = g[name][i]
                values[name] = v.decode() if isinstance(v, bytes) else (int(v) if name == "seed" else
                                                                         (str(v) if isinstance(v, str) else float(v)))
            rows.append(CheckRow(**values))
        # a check stored by an older vtsi did not record the cases it read: the file's (a resumed
        # sweep may have more now: its verdict is then that of a sweep incomplete when checked)
        cases = (int(g.attrs["cases_done"]), int(g.attrs["cases_total"])) if "cases_total" in g.attrs \
            else (results.n_done, results.n_cases)
        speed_grid = str(g.attrs.get("speed_grid", ""))      # '' in a check stored by an older vtsi
    bridge = results.bridge()
    return CheckResult(settings, rows, *cases, bridge=bridge_text(bridge), speed_grid=speed_grid,
                       bridge_model=bridge_model_text(results, bridge),
                       frequency_limits=frequency_limits_text(bridge), hslm_b=hslm_b_text(results, bridge))


def bridge_model_text(results, bridge):
    """The sweep's bridge model in words, as the check's text and the report's settings give it:
    FE, or modal with the frequency of its basis [Hz] against the EN cut-off (whether it is the
    default, :func:`default_basis_hz`, and what set it) and, where the results file holds them
    (``modal_frequencies_hz``), how many modes and the highest one's frequency (``results`` the
    :class:`~vtsi.sweep_results.SweepResults`, ``bridge`` its bridge record)."""
    settings = results.identity["settings"]
    kind = settings.get("bridge", "fe")
    if kind == "fe":
        return "FE model, time-stepped"
    f_max = modal_basis_hz(kind, settings.get("modal_hz"), bridge)
    how = "time-stepped" if kind == "modal-stepped" else "exact passages of moving forces, cars time-stepped"
    en = en_cutoff_hz(bridge)
    default = default_basis_hz(results, bridge)
    relation = f"{f_max / en:.3g} × the EN cut-off {significant_text(en)} Hz"
    if not settings.get("modal_hz"):                   # a file of an older vtsi: the default of then
        relation += ", the default of an older vtsi"
    elif abs(f_max - default) <= 1e-9 * default:
        relation += (", the default" if default <= CUTOFF_MARGIN * en * (1 + 1e-9) else
                     f", the default for the moments: {CUTOFF_MARGIN:g} × twice the "
                     f"{significant_text(default / CUTOFF_MARGIN / AXLE_PAIR_HARMONICS)} Hz at which the trains' "
                     f"closest axles pass at {max(results.identity['speeds_kmh']):g} km/h")
    if f_max < en * (1 - 1e-9):
        relation = f"below the EN cut-off {significant_text(en)} Hz"
    modes = np.ravel(np.asarray(bridge.get("modal_frequencies_hz", []), dtype=float))
    if not modes.size:                                  # a file of an older vtsi
        return (f"modal: its modes up to {significant_text(f_max)} Hz ({relation}; the results file does not hold "
                f"how many modes), {how}")
    return (f"modal: {_plural_of(modes.size, 'mode')} up to {significant_text(f_max)} Hz ({relation}; the highest at "
            f"{significant_text(modes.max())} Hz), {how}")


def frequency_limits_text(bridge):
    """One line of information: each deck's n₀ [Hz] of the bridge record ``bridge`` (/bridge,
    :func:`deck_first_frequencies`) against EN 1991-2 Figure 6.10 at its L (its span, or L_Φ of a
    continuous deck), :func:`vtsi.codes.en1991_2.frequency_limits_text`; decks that read alike
    are given once ('decks 1, 2: ...'). No verdict reads it; :func:`stored_check` reads it again
    from the results file, as it does the bridge's line."""
    spans = np.asarray(bridge["span_lengths_m"], dtype=float).ravel()
    decks, n0 = span_decks(bridge), deck_first_frequencies(bridge)
    readings = {}
    for d in range(len(n0)):
        if np.any(decks == d):
            readings.setdefault(en1991_2.frequency_limits_text(n0[d], spans[decks == d]), []).append(d)
    if len(n0) == 1:
        return f"EN 1991-2 Figure 6.10: {next(iter(readings))}"
    return "EN 1991-2 Figure 6.10: " + "; ".join(
        f"{'deck' if len(ds) == 1 else 'decks'} {', '.join(str(d + 1) for d in ds)}: {text}"
        for text, ds in readings.items())


SELF_WEIGHT_REFUSED = ("check: the sweep's displacements, rotations and moments include the bridge's self weight "
                       "(bridge_self_weight), and the EN criteria read the trains' effects: sweep without it (on a "
                       "linear bridge it does not change them)")


def check(results, settings=None):
    """Evaluate every criterion on ``results`` (a :class:`SweepResults` or a results file path)
    with ``settings`` (:class:`CheckSettings`; None: its defaults); a SweepError when no
    criterion can be evaluated (the sweep kept none of their outputs) or a deck acceleration
    output counts fewer frequencies than the EN cut-off."""
    settings = CheckSettings() if settings is None else settings
    if not isinstance(settings, CheckSettings):
        raise SweepError(f"check: settings must be CheckSettings, got {type(settings).__name__}")
    if not isinstance(results, (SweepResults, str, os.PathLike)):
        raise SweepError(f"check: results must be SweepResults or a results file path, got {type(results).__name__}")
    if not isinstance(results, SweepResults):
        results = SweepResults(results)
    if results.n_done == 0:
        raise SweepError("check: the results file holds no finished case")
    if results.identity["settings"].get("bridge_self_weight"):
        raise SweepError(SELF_WEIGHT_REFUSED)
    outputs = {o["name"]: o for o in results.identity["outputs"]}
    bridge = results.bridge()
    out = CheckResult(settings, cases_done=results.n_done, cases_total=results.n_cases, bridge=bridge_text(bridge),
                      bridge_model=bridge_model_text(results, bridge),
                      frequency_limits=frequency_limits_text(bridge), hslm_b=hslm_b_text(results, bridge))
    for rule in (_deck_acceleration, _dynamic_increment, _deflection, _end_rotation, _car_body,
                 _wheel_unloading):
        out.rows.extend(rule(results, outputs, bridge, settings))
    _coarse_speeds(out, coarse_resonances(results, bridge, settings.line_speed_kmh))
    if bool(bridge.get("track_on_a_structure", False)):
        for row in out.rows:
            if not row.criterion.startswith(("car_body", "wheel_unloading", "contact_loss")):
                row.note += ("; the track stands on other elements over a structure at most of its nodes (a rail "
                             "on its pads over the deck?): this row reads the track, not that structure")
    if not out.rows:
        raise SweepError("check: the sweep kept none of the outputs the criteria read (deck acceleration, deflection, "
                         "bending moment, end rotation, car-body acceleration, contact force): nothing to check")
    return out


def refuse_inputs(results, settings=None):
    """Raise what :func:`check` refuses on a sweep's inputs alone, read from ``results`` before
    any case ran (its bridge record and outputs): a deck acceleration output that counts fewer
    frequencies than the EN cut-off or holds no deck node (:func:`vtsi.workflow.refuse_before_sweep`)."""
    settings = CheckSettings() if settings is None else settings
    _deck_acceleration(results, {o["name"]: o for o in results.identity["outputs"]}, results.bridge(), settings)


# -- the speed grid --------------------------------------------------------------------------------
def _coarse_speeds(out, coarse):
    """Say in ``out`` (a CheckResult) that the sweep's speeds step across the resonances ``coarse``
    (:func:`vtsi.speed_grid.coarse_resonances`) more coarsely than the EN series, or over the
    speeds of a train without D (its resonances unknown, :class:`vtsi.speed_grid.UnknownResonances`)
    more coarsely than the series' fine step: in the notes of the rows read from envelopes against
    speed (:data:`PEAK_AT_RESONANCE`: the deck's rows, the car bodies and the contact forces);
    those with a limit (deck acceleration, deflection, car-body acceleration, wheel unloading,
    contact loss), all peaking at resonance, are then not checked (info) unless they fail (a
    peak the grid misses only adds to a FAIL); the verdict names them (``out.speed_grid``)."""
    if not coarse:
        return
    unknown = [c for c in coarse if isinstance(c, UnknownResonances)]
    coarse = [c for c in coarse if not isinstance(c, UnknownResonances)]
    governing = next((r for r in out.rows if r.criterion == "deck_acceleration" and r.train), None)
    if governing is not None:           # the governing train's resonances first, the nearest its speed first
        coarse = sorted(coarse, key=lambda c: (c.train != governing.train, abs(c.speed_kmh - governing.speed_kmh)))
        unknown = sorted(unknown, key=lambda c: c.train != governing.train)
    below = sum(not np.isfinite(c.step_kmh) for c in coarse)
    missed = (f" ({below} of them below the speeds swept, which start above the series' "
              f"{en1991_2.SPEED_SERIES_START_KMH:g} km/h)" if below else "")
    across = f"step across {_plural_of(len(coarse), 'resonance speed')}"
    without = f"{_plural_of(len(unknown), 'train')} without D"
    said = "; and ".join(
        ([f"{across} v = n D / i more coarsely than the EN 1991-2 6.4.6.2 series (vtsi.sweep.en_speed_grid: from "
          f"{en1991_2.SPEED_SERIES_START_KMH:g} km/h, finer steps within ±10 % of each resonance){missed}: "
          f"{coarse_text(coarse)}"] if coarse else [])
        + ([f"step more coarsely than the EN 1991-2 6.4.6.2 series, which steps finely throughout for "
            f"{without} (vtsi.sweep.en_speed_grid): {coarse_text(unknown)}"] if unknown else []))
    said = (f"the sweep's speeds {said}; the peak may lie between the speeds swept: sweep the EN series "
            f"(--speeds en:LINE_SPEED) or finer speeds{' across them' if not unknown else ''}")
    short = " and ".join(([f"{across} more coarsely than the EN series"] if coarse else [])
                         + ([f"step more coarsely than the EN series for {without}"] if unknown else []))
    affected = [r for r in out.rows if r.criterion.startswith(PEAK_AT_RESONANCE)]
    first = next((r for r in affected if r.criterion == "deck_acceleration"), affected[0] if affected else None)
    for row in affected:
        unchecked = row.status == "pass" and row.criterion in WITH_A_VERDICT
        if unchecked:                   # a peak between the speeds swept may exceed the limit
            row.status = "info"
        if row is first:
            row.note += f"; {'not checked: ' if unchecked else ''}{said}"
        else:
            row.note += (f"; {'not checked: ' if unchecked else ''}the sweep's speeds {short} (see the "
                         f"{first.criterion} note): the peak may lie between them")
    out.speed_grid = "; and ".join(
        ([f"the speeds step across {_plural_of(len(coarse), 'resonance')} more coarsely than the EN "
          f"series{' or start above them' if below else ''} ({coarse_text(coarse, 2)})"] if coarse else [])
        + ([f"the speeds step more coarsely than the EN series for {without} ({coarse_text(unknown, 2)})"]
           if unknown else []))


# -- the load models -------------------------------------------------------------------------------
class LoadModels(NamedTuple):
    """What the sweep lacks of the HSLM trains EN 1991-2 6.4.6.1.1, Table 6.4 loads the bridge with
    (:func:`_load_models`)."""

    said: str          # the deck acceleration's note on them ('' when nothing is missing)
    unchecked: str     # why a row with a limit is not checked, with the remedy ('' when it is checked)
    remedy: str        # 'sweep again with ...' ('' when nothing is missing)


def _load_models(results, bridge):
    """:class:`LoadModels` of a sweep: which HSLM trains EN 1991-2 6.4.6.1.1, Table 6.4 loads the
    bridge's decks with (:func:`vtsi.codes.en1991_2.hslm_load_models`) it did not run. A sweep
    holding an HSLM train without all of them is no EN verification (``unchecked``): its deck
    acceleration and deflection, read from the dynamic analysis under them (EN 1991-2
    6.4.6.5(3)), are not checked unless they fail (a train not run can only add to a FAIL). A
    sweep of real trains only is a check for those trains: ``said`` still asks for HSLM-B on a
    short span, ``unchecked`` is ''."""
    spans, of = np.asarray(bridge["span_lengths_m"]), span_decks(bridge)
    decks = [spans[of == d] for d in sorted(set(of.tolist()))]
    needs = en1991_2.hslm_load_models(decks)
    names = {results.train_data(t)["name"] for t in results.trains}
    hslm = bool(names & {*en1991_2.HSLM_A, en1991_2.HSLM_B})
    below = en1991_2.HSLM_B_SPAN_RANGE[1]
    refusal = en1991_2.hslm_b_refusal(decks)           # '' when one sweep's HSLM-B loads every deck
    said, remedy, lacking = [], [], []
    if en1991_2.HSLM_B in names and refusal:      # an older vtsi's results file: it built HSLM-B from the first span
        said.append(f"HSLM-B is not a load model of this bridge: {refusal}")
    short = [k + 1 for k, need in enumerate(needs) if need == (en1991_2.HSLM_B,)]
    if short and en1991_2.HSLM_B not in names:
        own = f"deck{'s' * (len(short) > 1)} {', '.join(map(str, short))} as bridges of their own"
        said.append(f"EN 1991-2 6.4.6.1.1: a simply supported span under {below:g} m is checked with HSLM-B, which "
                    "this sweep does not hold" + ("" if not refusal else f" (a sweep runs one HSLM-B on decks of one "
                                                  f"span length under {below:g} m only: check {own})"))
        remedy.append("with HSLM-B (--trains HSLM-B)" if not refusal else f"check {own} with HSLM-B")
        lacking.append(en1991_2.HSLM_B)
    by_a = [k for k, need in enumerate(needs) if need == en1991_2.HSLM_A]
    if short and not by_a and names & set(en1991_2.HSLM_A):
        said.append(f"EN 1991-2 6.4.6.1.1, Table 6.4: HSLM-A is not a load model of a simply supported span under "
                    f"{below:g} m (HSLM-B is); the rows this sweep's HSLM-A trains govern count as a real train's")
    held = [n.removeprefix("HSLM-") for n in en1991_2.HSLM_A if n in names]
    missing = [n.removeprefix("HSLM-") for n in en1991_2.HSLM_A if n not in names]
    if by_a and missing and hslm:
        why = ((["Table 6.4 loads a continuous deck with all ten"] if any(len(decks[k]) > 1 for k in by_a) else [])
               + (["Table 6.4 lets a single critical train chosen by Annex E stand for them on a simply supported "
                   "span, a choice vtsi does not make"] if any(len(decks[k]) == 1 for k in by_a) else []))
        said.append(f"EN 1991-2 6.4.6.1.1: HSLM-A is its ten trains A1 to A10 (a continuous deck, or a span of "
                    f"{below:g} m or more), and this sweep holds " + (f"{', '.join(held)} only" if held else
                                                                      "none of them")
                    + f", without {', '.join(missing)} ({'; '.join(why)})")
        remedy.insert(0, "with all ten HSLM-A trains (--trains HSLM-A)")
        lacking.insert(0, f"HSLM-{', '.join(missing)}")
    again = f"sweep again {' and '.join(remedy)}" if remedy else ""
    unchecked = (f"not checked: a sweep of HSLM trains verifies the bridge to EN 1991-2 only with every train "
                 f"Table 6.4 asks for, and this one lacks {', '.join(lacking)}; {again}") if hslm and remedy else ""
    return LoadModels("; ".join(said), unchecked, again)


def hslm_b_source(results):
    """Where the N and d of the sweep's HSLM-B came from, in words for the report's train table:
    'given by the user' (the settings' ``hslm_b``) or 'as read by vtsi, not verified'
    (``results`` a :class:`~vtsi.sweep_results.SweepResults`; a file without the setting ran
    vtsi's reading, :func:`vtsi.models.trains.hslm_b_parameters`)."""
    if results.identity["settings"].get("hslm_b") is not None:
        return "given by the user (EN 1991-2 Figure 6.13)"
    return "EN 1991-2 Figure 6.13 as read by vtsi, not verified (--hslm-b N,d gives the figure's)"


def hslm_b_text(results, bridge):
    """One sentence when the sweep ran HSLM-B with the N and d of vtsi's straight-line reading of
    EN 1991-2 Figure 6.13 (not verified against the printed figure), which every verdict on it
    then rests on: the N and d it ran (the stored train's forces and spacing) and the span L [m]
    they were read at, and how to give the figure's own; '' when the sweep holds no HSLM-B or the
    user gave its N and d (``hslm_b``)."""
    if results.identity["settings"].get("hslm_b") is not None:
        return ""
    runs = [t for t in results.trains if results.train_data(t)["name"] == en1991_2.HSLM_B]
    if not runs:
        return ""
    data = results.train_data(runs[0])
    n, d = len(data["axle_offsets_m"]), float(data["characteristic_length_m"])
    span = float(np.asarray(bridge["span_lengths_m"], dtype=float).ravel()[0])
    return (f"HSLM-B's N = {n} and d = {d:.4g} m (L = {span:g} m) are vtsi's straight-line reading of EN 1991-2 "
            "Figure 6.13, not verified against the printed figure: give the figure's with --hslm-b N,d "
            "(PassageSettings(hslm_b=(N, d)))")


def _plural_of(n, word):
    return f"{n} {word}{'s' * (n != 1)}"


# -- the criteria ----------------------------------------------------------------------------------
def _governing(results, values, pick):
    """(train, speed, seed, index) of the extreme of ``values`` (n_train, n_speed, n_seed, ...)."""
    idx = np.unravel_index(pick(values), values.shape)
    return results.trains[idx[0]], float(results.speeds_kmh[idx[1]]), results.seeds[idx[2]], idx


def _outputs_of(outputs, response, cutoff=None):
    return [name for name, o in outputs.items() if o["response"] == response
            and (cutoff is None or (o.get("cutoff_hz") is not None) == cutoff)]


def _deck_acceleration(results, outputs, bridge, settings):
    """The deck acceleration of an output counting at least the EN cut-off's frequencies (one
    with ``cutoff='en'``, or the full response); an output counting fewer (a lower cut-off, or a
    modal bridge whose modes stop below it) is refused."""
    en_cutoff = en_cutoff_hz(bridge)            # of several decks, the largest of theirs
    sweep = results.identity["settings"]
    basis = modal_basis_hz(sweep.get("bridge", "fe"), sweep.get("modal_hz"), bridge)
    accel = _outputs_of(outputs, "accel")
    counted = {n: min((f for f in (outputs[n].get("cutoff_hz"), basis) if f is not None), default=None) for n in accel}
    short = [n for n in accel if counted[n] is not None and counted[n] < en_cutoff * (1 - 1e-9)]
    filtered = [n for n in _outputs_of(outputs, "accel", cutoff=True) if n not in short]
    name = (filtered or [n for n in _outputs_of(outputs, "accel", cutoff=False) if n not in short])[:1]
    if not name:
        if short:
            remedy = (f"the modal bridge's modes stop at modal_hz: take modal_hz >= {en_cutoff:.4g} Hz, or leave it "
                      "unset (the default: 1.1 x the cut-off, or more with moment outputs)"
                      if basis is not None and basis < en_cutoff else
                      "keep an output with cutoff='en' (or none: the full response)")
            raise SweepError(f"check: the deck acceleration output {short[0]!r} counts frequencies up to "
                             f"{counted[short[0]]:.4g} Hz, below the EN 1990 A2.4.4.2.1(4)P cut-off "
                             f"{en_cutoff:.4g} Hz: {remedy}")
        return []
    name = name[0]
    env, columns = results.column_envelopes(name)
    deck = deck_nodes(bridge)             # spans and overhangs: EN 1990 A2.4.4.2.1 reads the deck's peak
    on_deck = np.isin(np.asarray(columns), np.asarray(sorted(deck)))
    if not on_deck.any():
        raise SweepError(f"check: the deck acceleration output {name!r} holds no deck node (nodes "
                         f"{', '.join(str(int(c)) for c in columns)}): keep one at the deck's nodes (nodes='deck')")
    peak = np.where(on_deck, env[..., ABSMAX, :], np.nan)     # a pier's node or an approach's is no deck
    if np.all(np.isnan(peak)):
        return []
    train, speed, seed, idx = _governing(results, peak, np.nanargmax)
    limit = en1990_a2.deck_acceleration_limit(settings.track)
    value = float(peak[idx])
    if outputs[name].get("cutoff_hz") is not None:
        note = f"frequencies up to {counted[name]:.4g} Hz (modal projection)"
    elif basis is not None:
        note = f"frequencies up to {basis:.4g} Hz (the modal bridge's modes)"
    else:
        note = "the FE model's full response: no EN cut-off output was kept"
    x_peak = dict(zip(bridge["deck_nodes"].tolist(), bridge["deck_x_m"].tolist())).get(int(columns[idx[-1]]))
    tol = x_tolerance(bridge)
    for _, a, b in overhangs(bridge):
        if x_peak is not None and abs(x_peak - a) > tol and min(a, b) - tol <= x_peak <= max(a, b) + tol:
            note += (f"; the peak is on the overhang from x = {min(a, b):g} to {max(a, b):g} m (deck: it carries "
                     "the track)")
    # the damping ratio the time step must resolve; None: exact modal passages (self weight: refused)
    zeta = step_ratio(sweep.get("bridge", "fe"), sweep.get("cars", "force"), sweep.get("damping"))
    # the highest frequency EN counts in this output: a modal basis above the cut-off is margin
    f_top, dt = min(counted[name] or en_cutoff, en_cutoff), float(sweep.get("dt", 0.0))
    steps = 1.0 / (f_top * dt) if dt > 0 else math.inf
    coarse = (_coarse_step(value, limit, "fail" if value > limit else "pass", step_effect(dt, f_top, zeta),
                           zeta is None, "the cut-off") if steps < MIN_STEPS_PER_PERIOD else None)
    too_coarse = coarse is not None and coarse[0] == "info"
    models = _load_models(results, bridge)
    if models.said:
        note += f"; {models.said}"
    fails = value > limit and not too_coarse
    if models.unchecked:
        note += f"; {models.unchecked}" if not fails else f"; a FAIL stands: the trains not run can only add to it; " \
                                                          f"{models.remedy}"
    read = deck & set(np.asarray(columns).tolist())
    if read != deck:        # EN: the maximum along the track; a subset of nodes may miss it
        note += (f"; read at {len(read)} of the deck's {len(deck)} nodes only (output {name!r}): the deck's "
                 "maximum may lie elsewhere")
    if dt > 0 and not resolves(dt, f_top, zeta):
        finer = dt_resolving(f_top, zeta)
        effect = ("the peak may fall between the samples and read low by up to 1 - cos(pi f dt) (exact passages have "
                  "no step error, but their output is sampled)" if zeta is None else
                  f"the peak is not converged in dt and may be off either way ({step_error_text(dt, f_top, zeta)})")
        note += (f"; dt = {1e3 * dt:g} ms {'samples' if zeta is None else 'steps'} the highest counted frequency, "
                 f"{f_top:.4g} Hz, {steps:.3g} times a period: {effect}; take dt <= {1e3 * finer:g} ms "
                 f"({step_rule_text(zeta)}: the default)")
        if coarse is not None:
            note += coarse[1]
    top, start = float(np.max(results.speeds_kmh)), en1991_2.SPEED_SERIES_START_KMH
    if top < start:
        note += (f"; the sweep's speeds stop at {top:g} km/h, below {start:g} km/h (40 m/s), where EN 1991-2 "
                 f"6.4.6.2(3)'s series starts (speeds are km/h: {top:g} m/s would be {3.6 * top:g} km/h)")
    damped, overdamped = _rayleigh_note(sweep, bridge)
    note += damped
    if overdamped and value <= limit:
        note += "; not checked: a PASS with a mode damped above the ratio stated is not sure"
    rings = _rings(sweep)
    if rings:
        note += (f"; not checked: {RINGING}, and the deck's acceleration grows as dt shrinks (an ICE3 on a 20 m span: "
                 f"2.3 to 13.8 m/s^2 for dt 2 to 0.25 ms); {RINGING_REMEDY}: 2.2 at every dt")
    flown = int(np.sum(_flown(results)))
    if flown:
        note += (f"; {'not checked: ' if value <= limit else ''}{flown} of {results.n_done} passages had a wheel fly "
                 f"on a deck (contact='lcp'), and each touch-down, a rigid point impact, excites the deck's modes up "
                 f"to the cut-off: the deck acceleration then grows as dt falls, whatever the rows ({LCP_DECK}); "
                 "read it from a sweep with bilateral contact or moving forces")
    unchecked = (rings or too_coarse or (overdamped and value <= limit) or (models.unchecked and not fails)
                 or (flown and value <= limit))
    return [CheckRow("deck_acceleration", "EN 1990 A2.4.4.2.1(4)P", value, "m/s^2", limit, value / limit,
                     "info" if unchecked else ("fail" if fails else "pass"), train, speed, seed,
                     node_text(bridge, columns[idx[-1]]), f"{settings.track.replace('_', ' ')} track; {note}")]


def _dynamic_increment(results, outputs, bridge, settings):
    """φ'_dyn and the comparison with Φ × LM71, on the mid-span deflections (downward: the
    envelope's minimum) and, when the sweep kept them, the mid-span bending moments (sagging:
    the maximum) and the bending moments over the intermediate supports of continuous decks
    (hogging: the minimum; ``_support_moment`` rows, from the first moment output holding them);
    the moments of track elements that carry less than :data:`LOCAL_MOMENT_SHARE` of their
    span's moment are local, not read (:func:`moment_shares`)."""
    rows = []
    moments = _outputs_of(outputs, "moment", cutoff=False)
    shares = moment_shares(results, moments, bridge)
    for response, row, suffix, what in (("disp", MIN, "", "mid-span deflection"),
                                        ("moment", MAX, "_moment", "mid-span bending moment")):
        for name in _outputs_of(outputs, response, cutoff=False):
            rows.extend(_increment_rows(results, name, row, suffix, what, bridge, settings,
                                        shares=shares if response == "moment" else None))
    held = [n for n in moments if support_columns(results.column_envelopes(n)[1], bridge)]
    if held:                                           # the first moment output holding them (the default's)
        rows.extend(_increment_rows(results, held[0], MIN, "_support_moment", "hogging bending moment over the "
                                    "intermediate supports", bridge, settings, supports=True, shares=shares))
    basis_note = _moment_basis_note(results, bridge)
    for r in rows:
        if r.criterion.endswith("_moment"):
            r.note += basis_note
    piers = [n for _, _, nodes in intermediate_supports(bridge) for n in nodes[:1]]
    if moments and piers and not held:                 # a continuous deck whose sweep kept no moment over its piers
        for r in rows:
            if r.criterion.endswith("_moment"):
                r.note += (f"; the hogging moment over the intermediate support{'s' * (len(piers) > 1)} (node"
                           f"{'s' * (len(piers) > 1)} {', '.join(map(str, piers))}) is not read: no bending-moment "
                           "output of the sweep holds it (keep one at nodes='piers', as the default outputs do)")
    return rows


class StaticReference(NamedTuple):
    """EN 1991-2 6.4.6.5(3)'s static reference at some places of an output (:func:`static_reference`)."""

    values: np.ndarray          # (n,) its static value, α = 1, in the output's units (the row's sign)
    models: np.ndarray          # (n,) which gives it: 'LM71', or 'SW/0' where that is more unfavourable
    continuous: np.ndarray      # (n,) bool: the place is on a continuous deck (SW/0 counted)
    sw0_missing: bool           # a continuous deck's place whose SW/0 the file does not hold (LM71 alone)


class StaticRatios(NamedTuple):
    """The dynamic-to-static ratios of an output at some places (:func:`mid_span_ratios`)."""

    ratio: np.ndarray           # (n_train, n_speed, n_seed, n) y_dyn / y_stat under the same train
    columns: list               # (n,) the output's columns there
    train_static: np.ndarray    # (n_train, n) the static values under the trains
    reference: StaticReference  # the static reference there (LM71, or SW/0 on a continuous deck)


def _continuous_spans(bridge):
    """(n_spans,) bool: each span is one of a continuous deck's (its deck has two spans or more),
    which EN 1991-2 6.3.3(1)P loads with SW/0 as well as LM71 (a simply supported span takes
    LM71 alone, though SW/0 exceeds it on some: an 18 m span's mid-span moment by 3.3 %, its
    deflection by 6.1 %)."""
    decks = span_decks(bridge)
    return np.bincount(decks)[decks] > 1


def static_reference(static, row, columns, continuous):
    """The static reference of EN 1991-2 6.4.6.5(3) at ``columns`` of an output's static envelopes
    ``static`` (:class:`~vtsi.influence.StaticEnvelopes`), its envelope row ``row`` (MIN or MAX):
    LM71's value, or where ``continuous`` ((n,) bool: on a continuous deck) SW/0's when that is
    more unfavourable (farther on the row's side; EN 1991-2 6.3.3(1)P, Eq. 6.15's Φ × (LM71 "+"
    SW/0)); a file without SW/0 gives LM71's alone, ``sw0_missing`` saying so where a place is
    on a continuous deck."""
    continuous = np.asarray(continuous, dtype=bool)
    lm71 = static.lm71[row, columns]
    if static.sw0 is None:
        return StaticReference(lm71, np.full(len(columns), "LM71"), continuous, bool(continuous.any()))
    sw0 = static.sw0[row, columns]
    sign = -1.0 if row == MIN else 1.0
    by_sw0 = continuous & (sign * sw0 > sign * lm71)
    return StaticReference(np.where(by_sw0, sw0, lm71), np.where(by_sw0, "SW/0", "LM71"), continuous, False)


def mid_span_ratios(results, name, row, bridge):
    """The dynamic-to-static ratios of output ``name`` at each span's middle
    (:class:`StaticRatios`): y_dyn / y_stat of the envelope row ``row`` (MIN: the downward
    deflection, MAX: the sagging moment) over the static value under the same train, at the
    mid-span columns, with the static values under the trains and the static reference
    (:func:`static_reference`); None when the sweep kept no static values or no mid-span column
    of ``name``. A ratio whose static value has not the row's sign (no downward deflection, no
    sagging moment: a 'mid-span' over a support) is NaN. ``bridge``: the results file's bridge
    record (:meth:`SweepResults.bridge`)."""
    columns = results.column_envelopes(name)[1]
    mid = span_columns(columns, bridge)
    kept = [k for k, c in enumerate(mid) if c >= 0]
    return _ratios(results, name, row, [mid[k] for k in kept], _continuous_spans(bridge)[kept])


def support_ratios(results, name, bridge):
    """:func:`mid_span_ratios` of the hogging moment (the envelope's minimum, negative) of the
    moment output ``name`` over the intermediate supports of continuous decks (its columns there,
    :func:`vtsi.deck_record.intermediate_supports`): M_dyn / M_stat, both hogging, the static
    reference the more unfavourable of LM71 and SW/0; or None (no static values, no such
    column)."""
    places = support_columns(results.column_envelopes(name)[1], bridge)
    return _ratios(results, name, MIN, [c for c, _, _ in places], np.ones(len(places), dtype=bool))


def _ratios(results, name, row, columns, continuous):
    """:class:`StaticRatios` of output ``name``'s envelope row ``row`` at its ``columns``, each on a
    continuous deck or not (``continuous``; see :func:`mid_span_ratios`), or None."""
    static = results.static(name)
    if static is None or not columns:
        return None
    env = results.column_envelopes(name)[0]
    stat = static.trains[:, row, :][:, columns]               # the same sign as the envelope row
    usable = _of_the_sign(stat, row)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = env[..., row, :][..., columns] / np.where(usable, stat, np.nan)[:, None, None, :]
    return StaticRatios(ratio, columns, stat, static_reference(static, row, columns, continuous))


class MomentShares(NamedTuple):
    """The share of its span's moment that the track elements carry at each span's middle
    (:func:`moment_shares`); NaN (and model '') where not known."""

    share: np.ndarray           # (n_spans,) track / free_body [-]
    track: np.ndarray           # (n_spans,) [N·m] the track elements' sagging moment under the static reference
    free_body: np.ndarray       # (n_spans,) [N·m] the span's free-body moment under the same load model
    models: np.ndarray          # (n_spans,) which load model: 'LM71' or 'SW/0'


def moment_shares(results, names, bridge):
    """:class:`MomentShares` at each span's middle, read from the first of the moment outputs
    ``names`` that holds it with static values: the track elements' most unfavourable sagging
    moment there under the static reference (LM71, or SW/0 where a continuous deck takes it:
    :func:`static_reference`) over the span's free-body moment under the same load model
    (:func:`free_body_moment`). A beam deck carries all of a section's moment: on a simply
    supported span the free-body moment, on a continuous deck or a frame less (the support
    moments take part of it); a share below :data:`LOCAL_MOMENT_SHARE` is a member's own
    bending. Not known where no output holds the middle, or the middle is on a support."""
    ends = np.asarray(bridge["span_ends_m"], dtype=float).reshape(-1, 2)
    deck_x, tol = dict(zip(bridge["deck_nodes"].tolist(), bridge["deck_x_m"].tolist())), x_tolerance(bridge)
    out = MomentShares(*(np.full(len(ends), np.nan) for _ in range(3)), np.full(len(ends), "", dtype=object))
    continuous = _continuous_spans(bridge)
    for name in names:
        static = results.static(name)
        columns = results.column_envelopes(name)[1]
        todo = [(k, c) for k, c in enumerate(span_columns(columns, bridge)) if c >= 0 and not out.models[k]]
        if static is None or not todo:
            continue
        reference = static_reference(static, MAX, [c for _, c in todo], continuous[[k for k, _ in todo]])
        for (k, c), track, model in zip(todo, reference.values, reference.models):
            x, (a, b) = deck_x.get(int(columns[c]), np.nan), ends[k]
            if track > 0.0 and a + tol < x < b - tol:
                free = free_body_moment(a, b, x, str(model))
                out.share[k], out.track[k], out.free_body[k], out.models[k] = track / free, track, free, str(model)
    return out


def free_body_moment(a, b, x, model):
    """The most unfavourable sagging moment [N·m] at ``x`` of a simply supported span from ``a``
    to ``b`` [m] under load model ``model`` ('LM71' or 'SW/0', α = 1, on the span only): the
    free-body moment M = R (x − a) − Σ P (x − x_P) over the loads left of x, R the reaction at
    ``a``, whatever carries it inside the span (a truss, girders under a stringer). Placed by
    :class:`~vtsi.influence.InfluenceLines` on a beam of two elements meeting at ``x``, whose
    moment influence line there is that triangle exactly (its stiffness does not enter)."""
    beam = Model()
    for tag, at in enumerate((a, x, b), start=1):
        beam.node(tag, float(at), 0.0)
    beam.fix(1, 1, 1, 0)
    beam.fix(3, 0, 1, 0)
    for tag in (1, 2):
        beam.element("elasticBeamColumn", tag, (tag, tag + 1), A=1.0, E=1.0, I=1.0, rho=1.0)
    lines = InfluenceLines(beam, Track(beam, [1, 2]), moments=[2])
    return float((lines.sw0_envelope() if model == "SW/0" else lines.lm71_envelope())[1, 0])


def _local_places(shares, spans):
    """Whether the track elements' moment at a place is local: the shares (:class:`MomentShares`)
    at the middles of its ``spans`` (the span of a mid-span place; both spans beside a support)
    are known for one at least and all below :data:`LOCAL_MOMENT_SHARE`."""
    known = _known(shares, spans)
    return bool(known) and all(shares.share[k] < LOCAL_MOMENT_SHARE for k in known)


def _known(shares, spans):
    """The ``spans`` whose middle's share (:class:`MomentShares`) is known."""
    return [k for k in spans if np.isfinite(shares.share[k])]


def _local_text(shares, spans, supports):
    """Why the track elements' moment at a place is local (:func:`_local_places`), naming the
    shares at the middles of ``spans``."""
    known = _known(shares, spans)
    each = "; ".join(f"span {k + 1}: {100 * shares.share[k]:.3g} %, {shares.track[k] / 1e3:.4g} of "
                     f"{shares.free_body[k] / 1e3:.5g} kN m under {shares.models[k]}" for k in known)
    where = ("at the middles of the spans beside the support" if supports else
             "at the span's middle" if len(known) == 1 else "at the spans' middles")
    return (f"the track elements carry less than {100 * LOCAL_MOMENT_SHARE:g} % of the span's bending moment "
            f"{where} ({each}; of the span's free-body moment R x - sum P (x - x_P) as a simply supported span "
            "under the same load model): they are a chord or a stringer of a structure that carries the span's "
            "bending (a truss, a track beam on cross girders), and their moment is their own bending between the "
            f"points that carry them{', over the support too' if supports else ''}, not the span's: the deflection "
            "and deck acceleration rows read the structure")


def _reference_note(reference, j):
    """What a row says of the static reference ``reference`` (:class:`StaticReference`) at its
    place ``j``: that SW/0 was weighed on a continuous deck, or that it could not be."""
    if reference.sw0_missing:
        return SW0_MISSING
    if reference.continuous[j]:
        return f"; {_weighed(reference.models[j])}"
    return ""


def _weighed(model):
    """'SW/0 exceeds LM71 there, ...': which of the two a continuous deck's place reads."""
    other = "LM71" if model == "SW/0" else "SW/0"
    return f"{model} exceeds {other} there, and a continuous deck takes the more unfavourable: EN 1991-2 6.3.3(1)P"


def _nanmax(values, axis):
    """np.nanmax over ``axis`` with NaN (not a RuntimeWarning) where every value is NaN."""
    values = np.asarray(values, dtype=float)
    top = np.max(np.where(np.isnan(values), -np.inf, values), axis=axis, initial=-np.inf)
    return np.where(np.isneginf(top) & np.all(np.isnan(values), axis=axis), np.nan, top)


def _of_the_sign(values, row):
    """Where ``values`` have the sign of the envelope row ``row`` (MIN: < 0, MAX: > 0), beyond
    1e-9 of the largest magnitude (a value of rounding size is none)."""
    values = np.asarray(values, dtype=float)
    sign = -1.0 if row == MIN else 1.0
    scale = np.nanmax(np.abs(values), initial=0.0)
    return np.isfinite(values) & (sign * values > 1e-9 * scale) if scale > 0 else np.zeros(values.shape, dtype=bool)


def _increment_rows(results, name, row, suffix, what, bridge, settings, supports=False, shares=None):
    """The ``dynamic_increment<suffix>`` and ``dynamic_vs_lm71<suffix>`` rows of output ``name``'s
    envelope row ``row`` at the spans' middles, or with ``supports`` (a moment output, row MIN)
    over the intermediate supports of continuous decks (Φ and φ'' of the support's deck); the
    second against Φ α × the static reference, LM71 or on a continuous deck the more
    unfavourable of LM71 and SW/0 (:func:`static_reference`), the note naming which. With
    ``shares`` (the moment outputs' :class:`MomentShares`) the places where the track elements'
    moment is local (:func:`_local_places`) are not read, and where every place is, the rows
    keep their values, not checked (status info, no reference), their notes saying why."""
    columns = results.column_envelopes(name)[1]
    if supports:
        places = support_columns(columns, bridge)
        ratios = support_ratios(results, name, bridge)
        kept = [k for _, k, _ in places]                                    # the span (deck) of each column
        labels = [f"the support at x = {x:g} m" for _, _, x in places]
        sense, at = "hogging", "the intermediate supports"
    else:
        ratios = mid_span_ratios(results, name, row, bridge)
        kept = [k for k, c in enumerate(span_columns(columns, bridge)) if c >= 0]    # the span of each column
        labels = [f"span {k + 1}" for k in kept]
        sense, at = "downward" if row == MIN else "sagging", "the spans' middles"
    if ratios is None:
        return []
    ratio, spans, stat, reference = ratios
    lacking = [labels[j] for j in range(len(kept)) if not np.all(_of_the_sign(stat, row)[:, j])]
    by = "a train" if len(results.trains) > 1 else "the train"
    if not lacking:
        gap = ""
    elif supports:
        gap = f"; {', '.join(lacking)} not read: no {sense} static value there under {by}"
    else:
        gap = (f"; span{'s' if len(lacking) > 1 else ''} {', '.join(s.removeprefix('span ') for s in lacking)} "
               f"not read: {'their middles have' if len(lacking) > 1 else 'its middle has'} no {sense} static value "
               f"under {by} (the node is on a support, or the span is not loaded there)")
    beside = [[k, k + 1] if supports else [k] for k in kept]     # the spans whose middles tell a place's share
    local = np.array([shares is not None and _local_places(shares, ks) for ks in beside], dtype=bool)
    unchecked = ""
    if local.all():
        unchecked = _local_text(shares, sorted({k for ks in beside for k in ks}), supports)
    elif local.any():                                 # read the places where the track carries the span
        ratio = np.where(local, np.nan, ratio)
        gap += "".join(f"; {labels[j]} not read: {_local_text(shares, beside[j], supports)}"
                       for j in np.flatnonzero(local))
    if np.all(np.isnan(ratio)):
        if not lacking or np.all(np.isnan(results.column_envelopes(name)[0][..., row, :])):
            return []          # no finished case
        return [CheckRow("dynamic_increment" + suffix, "EN 1991-2 6.4.6.5(3)", np.nan, "-",
                         note=f"not evaluated: phi'_dyn of the {what} ({name}) needs a {sense} static value{gap}")]
    train, speed, seed, idx = _governing(results, ratio, np.nanargmax)
    phi_dyn = float(ratio[idx]) - 1.0
    rows = [CheckRow("dynamic_increment" + suffix, "EN 1991-2 6.4.6.5(3)", phi_dyn, "-", train=train,
                     speed_kmh=speed, seed=seed, where=node_text(bridge, columns[spans[idx[-1]]]),
                     note=f"phi'_dyn of the {what} ({name}{_places_text(columns, spans, places) if supports else ''})"
                          f" against its static value under the same train"
                          f"{_truncation_note(results, bridge)}{gap}"
                          + (f"; not checked: {unchecked}" if unchecked else ""))]
    L_phi, Phi, phi2, share = (f[kept] if np.ndim(f) else f for f in _design_factors(results, bridge, settings))
    ran = ~np.all(np.isnan(ratio), axis=(1, 2))                  # a train with no finished case (incomplete sweep): NaN
    per_train = np.full(ran.shape, np.nan)
    per_train[ran] = _nanmax(ratio.transpose(0, 3, 1, 2)[ran], axis=(1, 2)) - 1.0   # φ'_dyn per train and place
    design = (1.0 + per_train + share * phi2[None, :]) * np.abs(stat)     # (n_train, n_places)
    static = Phi * settings.alpha * np.abs(reference.values)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(_of_the_sign(reference.values, row)[None, :], design / static[None, :], np.nan)
    if np.all(np.isnan(r)):
        by = "LM71/SW/0" if reference.continuous.any() and not reference.sw0_missing else "LM71"
        rows.append(CheckRow("dynamic_vs_lm71" + suffix, "EN 1991-2 6.4.6.5(3), Annex C", np.nan, "-", 1.0,
                             np.nan, "info", note=f"not evaluated: {what}: {by} gives no {sense} static value at "
                                                  f"{at} read{gap}"))
        return rows
    i, j = np.unravel_index(np.nanargmax(r), r.shape)
    value, model = float(r[i, j]), str(reference.models[j])
    governs = ("" if unchecked else ": the dynamic analysis governs" if value > 1.0 else
               f": Phi x {model} covers the dynamic effects")       # local: no reference to hold the value to
    y = "M" if suffix.endswith("moment") else "y"
    rows.append(CheckRow("dynamic_vs_lm71" + suffix, "EN 1991-2 6.4.6.5(3), Annex C", value, "-",
                         np.nan if unchecked else 1.0, np.nan if unchecked else value, "info",
                         results.trains[i], np.nan, -1, node_text(bridge, columns[spans[j]]),
                         f"{what}: (1 + phi'dyn + {share:g} phi'') {y}_train / (Phi alpha {y}_{model}) = {value:.3f}"
                         f"{governs} (L_Phi = {L_phi[j]:.3g} m, Phi = {Phi[j]:.3f}, phi'' = {phi2[j]:.3f}, "
                         f"alpha = {settings.alpha:g}"
                         + (f"; {y}_train = {stat[i, j] / 1e3:.5g} kN m static under {results.trains[i]}, "
                            f"{y}_{model} = {reference.values[j] / 1e3:.5g} kN m" if supports else "")
                         + f"){_reference_note(reference, j)}{_irregular_note(results)}{gap}"
                         + (f"; not checked: {unchecked}" if unchecked else "")))
    return rows


def _places_text(columns, spans, places):
    """': node 11 at x = 20 m, ...': the columns read over the intermediate supports."""
    return ": " + ", ".join(f"node {int(columns[c])} at x = {x:g} m" for c, (_, _, x) in zip(spans, places))


def _design_factors(results, bridge, settings):
    """Per span (n_spans,): L_Φ [m], Φ and φ'' of EN 1991-2 6.4.5.2, Annex C (φ'' at the sweep's
    highest speed), and the share of φ'' counted (6.4.6.5(3): ½ for careful maintenance, 1 for
    standard). L_Φ and n₀ are those of the span's deck (Table 6.2: its span, or k × the mean span
    of a continuous one; n₀ its own first frequency, :func:`deck_first_frequencies`): two simply
    supported decks side by side are two L_Φ, not one continuous, and a 30 m deck beside a 15 m
    one keeps its own n₀."""
    spans, decks = np.asarray(bridge["span_lengths_m"], dtype=float), span_decks(bridge)
    by_deck = {d: en1991_2.determinant_length(spans[decks == d]) for d in set(decks.tolist())}
    L_phi = np.array([by_deck[d] for d in decks.tolist()])
    Phi = np.array([en1991_2.dynamic_factor(L, settings.maintenance) for L in L_phi])
    v_max = float(np.max(results.speeds_kmh)) / 3.6
    n0 = deck_first_frequencies(bridge)[decks]
    phi2 = np.array([en1991_2.track_irregularity_increment(L, f, v_max) for L, f in zip(L_phi, n0)])
    return L_phi, Phi, phi2, 0.5 if settings.maintenance == "careful" else 1.0


def _irregular_note(results):
    """'' on a smooth rail; else that φ'_dyn already holds the irregular rail φ'' stands for."""
    if results.identity["settings"].get("irregularity") is None:
        return ""
    return ("; phi'_dyn comes from an irregular rail and already holds what phi'' stands for (EN 1991-2 Annex C "
            "adds phi'' to a smooth-rail phi'_dyn): counted twice, on the safe side")


def _truncation_note(results, bridge):
    """What a modal sweep's displacements and moments leave out when no static correction put
    the truncated modes' quasi-static share back (cars, static_correction off; a sweep with self
    weight is refused); '' otherwise."""
    sweep = results.identity["settings"]
    basis = modal_basis_hz(sweep.get("bridge", "fe"), sweep.get("modal_hz"), bridge)
    corrected = sweep.get("cars", "force") == "force" and sweep.get("static_correction", True)
    if basis is None or corrected:
        return ""
    return f" (in the modal bridge's modes up to {basis:.4g} Hz, without the higher modes' static share)"


def default_basis_hz(results, bridge):
    """The default modal basis [Hz] of the sweep of ``results`` as vtsi takes it now
    (:func:`~vtsi.passage.default_modal_hz`: from the bridge record's cut-off, the outputs' kinds,
    the top speed and the trains' stored axles)."""
    ident = results.identity
    offsets = [results.train_data(t)["axle_offsets_m"] for t in results.trains]
    return default_modal_hz(bridge, [o["response"] for o in ident["outputs"]], max(ident["speeds_kmh"]), offsets)


def _moment_basis_note(results, bridge):
    """'' unless the sweep ran a modal bridge whose basis stops below the moments' default
    (:func:`default_basis_hz`: 1.1 × twice the frequency at which the trains' closest axles pass
    at the top speed, where above the cut-off's): then that the moments may read low, and what
    to take."""
    sweep = results.identity["settings"]
    basis = modal_basis_hz(sweep.get("bridge", "fe"), sweep.get("modal_hz"), bridge)
    needed = None if basis is None else default_basis_hz(results, bridge)
    if basis is None or basis >= needed * (1 - 1e-9):
        return ""
    corrected = (sweep.get("cars", "force") == "force" and not sweep.get("bridge_self_weight")
                 and sweep.get("static_correction", True))     # PassageSettings.static_correction: moving forces only
    missed = ("the static correction puts back only the higher modes' quasi-static share" if corrected else
              "passages of cars or with self weight get no static correction, so the higher modes' share is left "
              "out entirely")
    return (f"; the modal bridge's modes stop at {basis:.4g} Hz, below the {needed:.4g} Hz that holds the modes the "
            f"trains' closest axles drive at {max(results.identity['speeds_kmh']):g} km/h: {missed}, and the moments "
            "may read low (over the pier of a 2 x 20 m deck on bearings and piers, modes to 33 Hz: 6.3 % "
            f"low); sweep with modal_hz >= {needed:.4g} Hz (the default) or the FE bridge")


@dataclass
class NodeDeflection:
    """What the deflection rows read at one node of a span or an overhang (:func:`node_deflections`)."""

    node: int                   # its tag
    criterion: str              # 'deflection' (a span's node) or 'deflection_overhang'
    length: float               # [m] of its span or overhang (the limit: length / 600)
    reference: float            # [m] Φ α |y_stat| under the static reference, downward
    model: str                  # which gives it: 'LM71', or 'SW/0' (:func:`static_reference`)
    continuous: bool            # on a continuous deck: SW/0 weighed (or, sw0_missing, not held)
    sw0_missing: bool           # on a continuous deck, but the results file holds no SW/0: LM71 alone
    dynamic: np.ndarray         # (n_train, n_speed, n_seed) [m] max |y_dyn|, downward
    checked: np.ndarray         # (n_train, n_speed, n_seed) [m] max |y_dyn| + φ''/2 |y_stat,train|
    Phi: float                  # Φ of its deck's L_Φ
    phi2: float                 # φ'' of its deck's L_Φ and n₀


def node_deflections(results, name, bridge, settings):
    """The deflection the check reads at each node of output ``name`` on a span or an overhang
    (:class:`NodeDeflection`, in the output's column order; nodes off the decks left out), or None
    when the sweep kept no static values of ``name``: Φ α × the static reference's deflection
    (LM71's, or on a continuous deck the more unfavourable of LM71's and SW/0's,
    :func:`static_reference`) and (1 + φ'_dyn + φ''/2) × each train's, i.e. max |y_dyn| + φ''/2
    |y_stat,train| (φ'' whole for standard maintenance; EN 1991-2 6.4.6.5(3)), Φ and φ'' of the
    node's deck. The deflection rows are the largest of these against L/600; the report draws
    them against speed."""
    static = results.static(name)
    if static is None:
        return None
    env, columns = results.column_envelopes(name)
    deck_x = dict(zip(bridge["deck_nodes"].tolist(), bridge["deck_x_m"].tolist()))
    spans, ends = np.asarray(bridge["span_lengths_m"]), np.asarray(bridge["span_ends_m"]).reshape(-1, 2)
    _, Phi, phi2, share = _design_factors(results, bridge, settings)
    decks, hangs, tol = span_decks(bridge), overhangs(bridge), x_tolerance(bridge)
    continuous = _continuous_spans(bridge)
    train_static = np.abs(static.trains[:, MIN])
    read = []                             # (column, node, criterion, length, span of its deck)
    for c, node in enumerate(columns):
        x = deck_x.get(int(node), np.nan)
        inside = np.flatnonzero((ends[:, 0] - tol <= x) & (x <= ends[:, 1] + tol))
        if len(inside):
            k = f = int(inside[0])
            key, length = "deflection", spans[k]
        else:
            on = [h for h, (d, a, b) in enumerate(hangs) if min(a, b) - tol <= x <= max(a, b) + tol]
            if not on:            # off the deck: on the ground beyond its spans, or a joint
                continue
            d, a, b = hangs[on[0]]
            f = int(np.flatnonzero(decks == d)[0])
            key, length = "deflection_overhang", abs(b - a)
        read.append((c, int(node), key, float(length), f))
    if not read:
        return []
    reference = static_reference(static, MIN, [c for c, *_ in read], continuous[[f for *_, f in read]])
    out = []
    for j, (c, node, key, length, f) in enumerate(read):
        dynamic = np.abs(env[..., MIN, c])
        out.append(NodeDeflection(node, key, length, Phi[f] * settings.alpha * abs(float(reference.values[j])),
                                  str(reference.models[j]), bool(reference.continuous[j]),
                                  bool(reference.continuous[j]) and reference.sw0_missing, dynamic,
                                  dynamic + share * phi2[f] * train_static[:, c][:, None, None],
                                  float(Phi[f]), float(phi2[f])))
    return out


def _deflection(results, outputs, bridge, settings):
    """The deflection of every deck node under the more unfavourable of Φ α × the static
    reference (LM71, or on a continuous deck the more unfavourable of LM71 and SW/0: EN 1990
    A2.4.4.2.3(1), 'classified LM71 and where required classified SW/0') and (1 + φ'_dyn +
    φ''/2) × each train of the sweep (EN 1991-2 6.4.6.5(3): the dynamic analysis governs where
    that is larger), against L/600 of its span (EN 1990 A2.4.4.2.3(1)), Φ and φ'' of its deck's
    L_Φ (:func:`node_deflections`). An overhang's nodes (a cantilever carrying the track) are
    read the same way in a row of their own, ``deflection_overhang``, against L_c/600 of the
    overhang's length L_c for reference only (info): A2.4.4.2.3(1) gives L/600 for spans, no
    limit for a cantilever."""
    for name in _outputs_of(outputs, "disp", cutoff=False):
        nodes = node_deflections(results, name, bridge, settings)
        if nodes is None:
            continue
        share = _design_factors(results, bridge, settings)[3]
        models = _load_models(results, bridge)
        worst = {"deflection": None, "deflection_overhang": None}
        for n in nodes:
            limit = n.length / en1990_a2.DEFLECTION_SPAN_RATIO
            at = n.checked
            case = np.unravel_index(np.nanargmax(at), at.shape) if np.any(np.isfinite(at)) else None
            value = max(n.reference, at[case] if case is not None else -np.inf)
            key = n.criterion
            if worst[key] is None or value / limit > worst[key][0] / worst[key][1]:
                worst[key] = (value, limit, n, None if value == n.reference else case)
        rows = []
        for key, found in worst.items():
            if found is None:
                continue
            value, limit, n, case = found
            weighed = f"; {_weighed(n.model)}" if n.continuous and not n.sw0_missing else ""
            rule = (f"the more unfavourable of Phi x alpha x {n.model} ({n.reference:.4g} m{weighed}; Phi = "
                    f"{n.Phi:.3f}, alpha = {settings.alpha:g}) and (1 + phi'dyn + {share:g} phi'') x each train "
                    f"(phi'' = {n.phi2:.3f}; EN 1991-2 6.4.6.5(3)); limit L/600")
            status = "pass" if value <= limit else "fail"
            clause = "EN 1990 A2.4.4.2.3(1), EN 1991-2 6.4.6.5(3)"
            if key == "deflection_overhang":
                status, clause = "info", "EN 1991-2 6.4.6.5(3)"
                rule = (rule.removesuffix("; limit L/600") + f"; reference L_c/600 of the overhang's length L_c = "
                        f"{n.length:g} m, not checked: EN 1990 A2.4.4.2.3(1) gives L/600 for spans, no limit for a "
                        "cantilever")
            if any(m.sw0_missing for m in nodes if m.criterion == key):
                rule += SW0_MISSING
            if status != "info" and models.unchecked:
                status = "info" if status == "pass" else status
                rule += (f"; {models.unchecked}" if status == "info" else
                         f"; a FAIL stands: the trains not run can only add to it; {models.remedy}")
            governs = f"{n.model} governs" if case is None else "the dynamic analysis governs"
            who = (n.model, np.nan, -1) if case is None else \
                (results.trains[case[0]], float(results.speeds_kmh[case[1]]), results.seeds[case[2]])
            rows.append(CheckRow(key, clause, value, "m", limit, value / limit, status, *who, node_text(bridge, n.node),
                                 f"{governs}: {rule}{'' if case is None else _irregular_note(results)}"))
        return rows
    return []


RAYLEIGH_SPREAD = 0.1    # a deck's n₀ Rayleigh damping gives a ratio more than this share off the stated ζ is noted


def _rayleigh_note(sweep, bridge):
    """(note, whether a mode is damped more than stated): '' and False unless the sweep stepped
    the FE bridge with its own ζ as Rayleigh damping and (a) a deck's n₀ gets a ratio more than
    RAYLEIGH_SPREAD below ζ: between the anchors (``damping_hz``, by default the model's n₀ and
    the largest cut-off: a short deck among longer ones), its resonances read high, on the safe
    side; or (b) a mode up to the cut-off gets more than RAYLEIGH_SPREAD above ζ: outside the
    anchors (a ``damping_hz`` above n₀, or below the cut-off), its resonances read low, on the
    unsafe side, and a PASS of the deck acceleration is not sure (a results file of an older vtsi
    lists no modes above each deck's n₃: those may be, where the ratio at the cut-off is more than
    RAYLEIGH_SPREAD above ζ). A deck's higher modes between
    the anchors get less than ζ with any anchors (docs/sweeps.md, "Damping"): not named. The
    remedy: the modal bridge, or anchors through the lowest n₀ and the cut-off where those leave
    nothing to note (one deck; decks of n₀ that close), else why no anchors can. Three decks on
    one track (10 m slab, 30 m span, 2 × 20 m), ζ 1 % through 4.635 and 118.5 Hz: the slab's n₀,
    13.25 Hz, got 0.44 %, and its acceleration read 5.52 m/s² where the modal bridge at ζ on every
    mode read 3.27 (a probe's); through the slab's n₀ and the cut-off, the 30 m span's n₀ got
    2.61 %, and the deck acceleration read 4.07 m/s² against 4.85; a 20 m span of n₀ 5 Hz
    through 12 and 45 Hz: 1.98 %, 3.34 m/s² PASS where ζ on every mode reads 5.19, FAIL; through
    5 and 10 Hz its n₃ (45.2 Hz) got 3.1 % and its acceleration read 8.5 % low."""
    zeta = sweep.get("damping")
    if sweep.get("bridge", "fe") != "fe" or not zeta:
        return "", False
    rows, cut = deck_frequencies_table(bridge), en_cutoff_hz(bridge)
    pair = sweep.get("damping_hz") or (float(np.ravel(bridge["frequencies_hz"])[0]), cut)
    modes = np.ravel(bridge.get("frequencies_to_cutoff_hz", []))     # not in a file of an older vtsi
    less, more = _rayleigh_off(zeta, pair, rows, modes)
    at_cut = float(rayleigh_ratio(cut, *rayleigh_coefficients(zeta, *pair)))
    if ("frequencies_to_cutoff_hz" not in bridge and at_cut > (1 + RAYLEIGH_SPREAD) * zeta
            and cut > rows[:, 2].min() * (1 + 1e-9)):          # modes between a deck's n3 and the cut-off
        more.append(f"any mode between a deck's n3 and the cut-off, which a results file of an older vtsi does not "
                    f"list, up to zeta = {100 * at_cut:.3g} % at the cut-off ({cut:.4g} Hz)")
    if not (less or more):
        return "", False
    said = [f"{', '.join(less)}: damped less, their resonances read high (on the safe side)" if less else "",
            f"{', '.join(more)}: damped more, their resonances read low (on the unsafe side)" if more else ""]
    anchors = (float(rows[:, 0].min()), cut)          # the remedy, where it leaves nothing to note
    still_less, still_more = _rayleigh_off(zeta, anchors, rows, modes)
    if not (still_less or still_more):
        remedy = (f", or take damping_hz through {'n0' if len(rows) == 1 else 'the lowest n0'} and the cut-off "
                  f"({anchors[0]:.4g} and {anchors[1]:.4g} Hz)")
    elif still_less:
        remedy = (f": one Rayleigh pair cannot damp decks of n0 {rows[:, 0].min():.4g} to {rows[:, 0].max():.4g} Hz "
                  "alike")
    else:
        remedy = f": through the lowest n0 and the cut-off, {', '.join(still_more)}"
    return (f"; Rayleigh damping through {pair[0]:.4g} and {pair[1]:.4g} Hz, not the {100 * zeta:.3g} % stated, "
            f"gives {'; '.join(p for p in said if p)}; the modal bridge (--bridge-model modal) damps every mode at "
            f"zeta{remedy}"), bool(more)


def _rayleigh_off(zeta, pair, rows, modes):
    """(less, more): what Rayleigh damping of ratio ``zeta`` through ``pair`` [Hz] gives more than
    RAYLEIGH_SPREAD off ζ, as 'name (f Hz) zeta = r %': less, of each deck's n₀ (``rows``
    (n_decks, 3) each deck's n₀, n₂, n₃ [Hz]); more, of those and of the bridge's ``modes`` up to
    the cut-off [Hz] (each not a deck's n₀, n₂, n₃ named 'mode k', its place among them), in
    ascending frequency."""
    alpha, beta = rayleigh_coefficients(zeta, *pair)
    deck = "" if len(rows) == 1 else "deck {}'s "
    less = [f"{deck.format(d + 1)}n0 ({f:.4g} Hz) zeta = {100 * r:.3g} %"
            for d, (f, r) in enumerate(zip(rows[:, 0], rayleigh_ratio(rows[:, 0], alpha, beta)))
            if r < (1 - RAYLEIGH_SPREAD) * zeta]
    named = [(f, f"{deck.format(d + 1)}n{(0, 2, 3)[k]}") for d, row in enumerate(rows) for k, f in enumerate(row)]
    named += [(f, f"mode {k + 1}") for k, f in enumerate(modes) if not np.any(np.isclose(f, rows, rtol=1e-6, atol=0))]
    named.sort(key=lambda item: item[0])
    more = [f"{name} ({f:.4g} Hz) zeta = {100 * r:.3g} %"
            for (f, name), r in zip(named, rayleigh_ratio([f for f, _ in named], alpha, beta))
            if r > (1 + RAYLEIGH_SPREAD) * zeta]
    return less, more


MIN_STEPS_PER_PERIOD = 4     # fewer steps (samples) a period of the cut-off, or of the rail: a row is held only when sure


END_ROTATION_CLAUSE = "EN 1990 A2.4.4.2.3, EN 1991-2 6.5.4.5.2"   # where EN limits end rotations (not checked)


def _end_rotation(results, outputs, bridge, settings):
    """The largest rotation at the decks' end supports (each deck's outermost spans' outer
    supports; an output's nodes there; at all its nodes, so said, when it has none there)."""
    deck_x = dict(zip(bridge["deck_nodes"].tolist(), bridge["deck_x_m"].tolist()))
    spans, decks, tol = np.asarray(bridge["span_ends_m"]).reshape(-1, 2), span_decks(bridge), x_tolerance(bridge)
    ends = sorted({float(x) for d in set(decks.tolist()) for x in (spans[decks == d][0, 0], spans[decks == d][-1, 1])})
    for name in _outputs_of(outputs, "rotation"):
        env, columns = results.column_envelopes(name)
        peak = np.maximum(np.abs(env[..., MIN, :]), np.abs(env[..., MAX, :]))
        at_end = [c for c, n in enumerate(columns.tolist())
                  if n in deck_x and min(abs(deck_x[n] - e) for e in ends) <= tol]
        supports = " and ".join(f"{e:g}" for e in ends)
        hangs = overhangs(bridge)
        whose = "the overhangs' free ends" if len(hangs) > 1 else "the overhang's free end"
        beyond = (f"; {whose} (x = "
                  f"{' and '.join(f'{b:g}' for _, _, b in hangs)} m) beyond {'them' if len(hangs) > 1 else 'it'} "
                  "not read") if hangs else ""
        where = (f"at the decks' end supports (x = {supports} m{beyond})" if at_end else
                 f"at the output's nodes, none at the decks' end supports (x = {supports} m)")
        if at_end:
            peak, columns = peak[..., at_end], columns[at_end]
        if np.all(np.isnan(peak)):
            continue
        train, speed, seed, idx = _governing(results, peak, np.nanargmax)
        return [CheckRow("end_rotation", END_ROTATION_CLAUSE, float(peak[idx]), "rad", train=train, speed_kmh=speed,
                         seed=seed, where=node_text(bridge, columns[idx[-1]]),
                         note=f"largest rotation of the deck under the trains {where} (no limit checked: EN 1990 "
                              "A2.4.4.2.3 leaves the end rotations of a ballasted deck to EN 1991-2 6.5.4.5.2, which "
                              "limits the vertical displacement of the deck end relative to the adjacent construction: "
                              "the rotation acting through the geometry of the deck end and its bearings (or a frame's "
                              "corner), which the model does not hold; for direct fastening the project sets the "
                              "limit)")]
    return []


def _case_text(results, idx):
    seed = results.seeds[idx[2]]
    return f"{results.trains[idx[0]]} {float(results.speeds_kmh[idx[1]]):g} km/h" + (f" seed {seed}" if seed >= 0 else "")


def _rail_step_note(results, bridge, value, limit, status):
    """(status, note) of a car row (``value`` against ``limit``, its own ``status`` 'pass', 'fail'
    or 'info'): the note '' unless the sweep ran cars on an irregular rail with a Δt giving the
    rail's shortest wavelength at its top speed fewer than STEPS_PER_CUTOFF_PERIOD steps a period
    (:func:`vtsi.passage.rail_frequency_hz`): then that the row is not converged in Δt. With fewer
    than MIN_STEPS_PER_PERIOD steps a period (the deck row's rule) the row is not checked ('info')
    unless it fails (:func:`_coarse_step`): a rail sampled so coarsely reads the rows low, by about
    1 − cos(π f Δt) (:func:`vtsi.passage.step_effect`; the rail's wave is an input the steps
    sample, not a mode with a damping ratio; measured: ΔQ/Q 0.094 at 10 ms, 3.6 steps a period,
    39 % below 0.154 at 0.25 ms, where the bound says 36 %)."""
    sweep = results.identity["settings"]
    top = float(np.max(results.speeds_kmh))
    f = rail_frequency_hz(sweep.get("irregularity"), sweep.get("cars", "force"), top)
    dt = float(sweep.get("dt") or 0.0)
    if f is None or not dt > 0 or resolves(dt, f):
        return status, ""
    steps, rule = 1.0 / (f * dt), dt_resolving(f)
    default = default_dt(bridge, f, step_ratio(sweep.get("bridge", "fe"), sweep.get("cars", "force"),
                                               sweep.get("damping")))
    take = (f"take dt <= {1e3 * rule:g} ms (the rail's {STEPS_PER_CUTOFF_PERIOD} steps a period; " +
            ("the default)" if default >= rule * (1 - 1e-9) else
             f"the default of this bridge and sweep, {1e3 * default:g} ms, is finer: it also resolves the deck's "
             "cut-off)"))
    note = (f"; not converged in dt: dt = {1e3 * dt:g} ms steps the rail's shortest wavelength "
            f"({top / 3.6 / f:g} m) at the top speed, {top:g} km/h ({f:.3g} Hz), {steps:.3g} times a "
            f"period, fewer than {STEPS_PER_CUTOFF_PERIOD} (an ICE3 at 300 km/h over a 20 m span, 'german-high' rail: "
            "Delta Q / Q 0.094 at 10 ms, 0.149 at 1.8 ms, 0.154 at 0.25 ms; on 'fra-1' a wheel lifted at 1.8 ms and "
            f"finer, none at 2 ms); {take}")
    if steps >= MIN_STEPS_PER_PERIOD or status == "info":
        return status, note
    status, said = _coarse_step(value, limit, status, step_effect(dt, f, None), True, "the rail's shortest wavelength")
    return status, note + said


def _coarse_step(value, limit, status, bound, low_only, what):
    """(status, note) of a row (``value`` against ``limit``, its ``status`` 'pass' or 'fail') read
    with fewer than MIN_STEPS_PER_PERIOD steps (samples) a period of ``what``: its value may be off
    by about ``bound`` [-] (:func:`vtsi.passage.step_effect`, an estimate: ΔQ/Q read 39 % low at
    10 ms where it says 36 %), low only when ``low_only`` (a sampled peak, a sampled rail: coarser
    reads lower), else either way. A FAIL stands when its least value, v (low only) or v (1 −
    bound), exceeds the limit; a PASS is never sure, and the row is then not checked ('info')."""
    least = value if low_only else value * (1.0 - bound)
    said = (f"fewer than {MIN_STEPS_PER_PERIOD} steps a period of {what} may read it "
            f"{'low' if low_only else 'off either way'} by {100 * bound:.3g} % or so")
    if status == "fail" and least > limit:
        return "fail", f"; {said}{'' if low_only else f', and {least:.4g} still exceeds the limit'}: the FAIL stands"
    return "info", f"; not checked: {said}"


def _free_end_note(bridge):
    """'' unless a track end of the results' bridge record sags more than
    :data:`~vtsi.track_ends.FREE_END_SAG` under the trains' heaviest static wheel load: then
    :func:`~vtsi.track_ends.free_end_text` (a step the cars' wheels read as an impact: the wheel
    unloading and contact loss rows may read it, the car bodies hardly: 0.006 m/s² measured);
    '' for a file of an older vtsi, which does not hold the ends."""
    if "track_end_nodes" not in bridge:
        return ""
    load = float(bridge["track_end_load_n"])
    text = free_end_text([TrackEnd(int(n), float(x), float(sag), load) for n, x, sag in
                          zip(bridge["track_end_nodes"], bridge["track_end_x_m"], bridge["track_end_sag_m"])])
    return f"; {text}" if text else ""


def _car_body(results, outputs, bridge, settings):
    for name in _outputs_of(outputs, "car_body_accel"):
        env, columns = results.column_envelopes(name)
        peak = env[..., ABSMAX, :]
        if peak.size == 0 or np.all(np.isnan(peak)):
            continue
        train, speed, seed, idx = _governing(results, peak, np.nanargmax)
        limit = en1990_a2.comfort_limit(settings.comfort)
        value = float(peak[idx])
        data = results.train_data(train)
        car = int(columns[idx[-1]])
        runouts = [results.train_data(t)["body_runout_s"] for t in results.trains]
        runout = max((float(r) for r in runouts if np.isfinite(r)), default=0.0)
        note = (f"level of comfort '{settings.comfort.replace('_', ' ')}'; the body's vertical acceleration at its "
                f"centre or over either bogie, while a wheel of the car is on a deck ({decks_text(bridge)}) and for "
                f"{runout:.3g} s after its last wheel left it (half a period of the car's lowest mode: its largest "
                "bridge-induced motion after the exit)")
        note += _whole_run_note(results, name, ABSMAX, value, "m/s^2", bridge)
        status, coarse = _rail_step_note(results, bridge, value, limit, "pass" if value <= limit else "fail")
        return [CheckRow("car_body_acceleration", "EN 1990 A2.4.4.3.1, Table A2.9", value, "m/s^2", limit,
                         value / limit, status, train, speed, seed, car_label(car, int(data["n_cars"])), note + coarse)]
    return []


def _whole_run_note(results, name, row, value, units, bridge, transform=None):
    """'' when the largest of output ``name``'s envelope row ``row`` over the whole run (ground
    before and after the bridge included) is the bridge's ``value``; else the note that gives it,
    with its case and place (``transform`` maps the row's values to the criterion's, e.g. ΔQ/Q)."""
    env, columns = results.column_envelopes(name, whole_run=True)
    values = env[..., row, :]
    if transform is not None:
        values = transform(values)
    if values.size == 0 or np.all(np.isnan(values)):
        return ""
    idx = np.unravel_index(np.nanargmax(values), values.shape)
    whole = float(values[idx])
    if not whole > value * (1 + 1e-9) + 1e-12:
        return ""
    return (f"; the largest over the whole run, {whole:.4g}{' ' + units if units != DIMENSIONLESS else ''} "
            f"({_case_text(results, idx)}, {wheel_or_car_place(results, name, idx, row, columns)}), is off the bridge "
            "(on the ground before or after it), not counted; the sweep keeps it (column_envelopes(..., "
            "whole_run=True))")


RINGING = "with 'hermite' rows Newmark's undamped rule rings after the rail's kinks at the supports"
RINGING_REMEDY = "take 'bspline' rows, exact_events or a damped integrator (HHT(0.9), Bathe)"


def _rings(sweep):
    """Whether a sweep's coupled passages ring: cars on 'hermite' rows without exact events, stepped
    by an integrator that does not dissipate (docs/theory: the constraint's kinks at the supports
    excite the highest modes, which such a rule never damps). The contact forces and the deck's
    accelerations ring; displacements, moments and car bodies do not (measured: within 1e-3)."""
    if sweep.get("cars", "force") == "force":
        return False
    try:
        integrator = make_integrator(sweep.get("integrator") or "Newmark")
    except VtsiError:          # an integrator this vtsi does not know: its dissipation is unknown
        return False
    return (sweep.get("interpolation") == "hermite" and not sweep.get("exact_events")
            and not integrator.dissipative)


def _static_loads(results, width):
    """Q (n_train, width) [N]: each train's contact wheels' static loads (NaN where it has fewer)."""
    Q = np.full((len(results.trains), width), np.nan)
    for i, train in enumerate(results.trains):
        data = results.train_data(train)
        static = data["static_wheel_loads_N"][data["contact_wheels"]]
        Q[i, : len(static)] = static
    return Q


LCP_DECK = ("a 15 m, 5.5 Hz span under an ICE3 at 360 km/h on a 'german-high' rail, 'hermite' rows: 6.45, 6.86, "
            "6.86, 6.75, 7.23 m/s^2 at dt 0.4 to 0.025 ms, bilateral 6.33 to 6.31; on 'fra-2' 14.2 to 21.4, bilateral "
            "10.9")
KINK_FLIGHT = ("an ICE3 at 360 km/h over a 15 m, 5.5 Hz span (smooth rail, its wheels flying where the rail kinks at "
               "the span's ends) read Delta Q / Q 0.26, 0.31, 0.39, 0.42 at dt 0.8, 0.4, 0.2, 0.1 ms with 'bspline' "
               "rows, 0.47, 0.41, 0.44, 0.43 with 'hermite' rows, 0.55, 0.45, 0.46, 0.44 and 0.45 at 0.05 ms with "
               "'hermite' rows and exact events")
KINK_REMEDY = ("take interpolation='hermite' with exact_events=True (--interpolation hermite --exact-events)")


def _flown(results):
    """(n_train, n_speed, n_seed) bool: the cases of ``results`` in which a wheel flew on a deck
    (raw contact, contact='lcp': :meth:`SweepResults.deck_flights`; NaN, a case not run or not
    counted, is no flight); False for a file of an older vtsi, which did not count flights."""
    flights = results.deck_flights()
    return np.asarray(False) if flights is None else flights > 0


def _flights(results, lifting):
    """(passages with a wheel that flew on a deck, those of them whose 10 ms mean never reached
    zero): counts over the cases of ``results`` (:func:`_flown`; ``lifting`` (n_train, n_speed,
    n_seed): the cases whose mean reached zero)."""
    flown = _flown(results)
    return int(np.sum(flown)), int(np.sum(flown & ~lifting))


def _flight_note(sweep, flown, done, status):
    """(status, note) of the wheel-unloading row when ``flown`` of the ``done`` passages had a
    wheel fly on a deck: with 'bspline' rows the unloading at a kink of the rail depends on dt
    and reads low (:data:`KINK_FLIGHT`): a PASS is not checked (info), a FAIL stands; with
    'hermite' rows without exact events a note (within 8 %); with 'hermite' rows and exact events
    nothing (with 'bspline' rows exact events take no kink)."""
    hermite = sweep.get("interpolation") == "hermite"     # None, with cars: 'bspline'
    if not flown or (hermite and sweep.get("exact_events")):      # events take kinks with 'hermite' rows only
        return status, ""
    said = f"; {flown} of {done} passages had a wheel fly on a deck (raw contact, however briefly): {KINK_FLIGHT}"
    if hermite:
        return status, (f"{said}; with 'hermite' rows and no exact events within 8 % of the converged value (low "
                        "at 0.4 ms): exact_events=True takes each kink at its own time")
    unsure = status == "pass"
    return ("info" if unsure else status), (f"{said}; {'not checked: ' if unsure else ''}with 'bspline' rows such a "
                                            f"flight, and the unloading it causes, depend on dt: {KINK_REMEDY}")


def _wheel_unloading(results, outputs, bridge, settings):
    for name in _outputs_of(outputs, "contact_force"):
        env, columns = results.column_envelopes(name)
        low = env[..., MIN, :]
        if low.size == 0 or np.all(np.isnan(low)):
            continue
        Q = _static_loads(results, low.shape[-1])
        unloading = 1.0 - low / Q[:, None, None, :]
        train, speed, seed, idx = _governing(results, unloading, np.nanargmax)
        value, limit = float(unloading[idx]), settings.unloading_limit
        done = results.n_done
        lifting = -_nanmax(-low, axis=-1) <= 0.0          # NaN (a case not run): no lift, no warning
        lifts = int(np.sum(lifting))
        counted = (f"counted while the wheel is on a deck ({decks_text(bridge)}; the 10 ms mean's reach beyond "
                   "its ends included)")
        note = ("Delta Q / Q = 1 - min contact force (its 10 ms mean) / static wheel load; the limit is the "
                f"project's (not an EN 1990 A2 clause); {counted}")
        note += _whole_run_note(results, name, MIN, value, "-", bridge,
                                transform=lambda v: 1.0 - v / Q[:, None, None, :])
        sweep = results.identity["settings"]
        rings = _rings(sweep)
        unchecked = (f"not checked: {RINGING}, and the contact force's minimum grows as dt shrinks (an ICE3 on a "
                     f"20 m span: Delta Q / Q 0.30 to 2.8 for dt 2 to 0.25 ms); {RINGING_REMEDY}: 0.08 at every dt"
                     ) if rings else ""
        if rings:
            note += "; " + unchecked
        if sweep.get("bridge", "fe") != "fe":
            note += ("; on a modal bridge the contact force misses the deck's local flexibility above the modes "
                     "(docs/modal.md: 20 % off the FE bridge on an irregular rail)")
        flown, brief = _flights(results, lifting)
        brief = (f"; {brief} of {done} passages had a wheel fly on a deck for less than the 10 ms mean shows (raw "
                 "contact: its gap opened, the mean stayed above zero), not counted") if brief else ""
        status, flight = _flight_note(sweep, flown, done, "info" if rings else ("pass" if value <= limit else "fail"))
        status, coarse = _rail_step_note(results, bridge, value, limit, status)
        lost, lost_note = _rail_step_note(results, bridge, float(lifts), 0.0,      # a lift seen is sure
                                          "info" if rings else ("pass" if lifts == 0 else "fail"))
        free_end = _free_end_note(bridge)
        rows = [CheckRow("wheel_unloading", "project criterion", value, "-", limit, value / limit, status,
                         train, speed, seed,
                         wheel_or_car_place(results, name, idx, MIN, columns, whole_run=False),
                         note + flight + coarse + free_end)]
        held = ("; bilateral contact held the wheels on the rail: what follows a lift is not physical, take "
                "contact='lcp'") if lifts and sweep.get("contact", "bilateral") == "bilateral" else ""
        whole, _ = results.column_envelopes(name, whole_run=True)
        ground = int(np.sum((-_nanmax(-whole[..., MIN, :], axis=-1) <= 0.0) & ~lifting))
        off = ""
        if ground:
            w = np.where(lifting[..., None], np.nan, whole[..., MIN, :])
            at = np.unravel_index(np.nanargmin(w), w.shape)
            off = (f"; {ground} of {done} passages lift a wheel off the bridge only (on the ground before or after "
                   f"it; the lowest: {_case_text(results, at)}, "
                   f"{wheel_or_car_place(results, name, at, MIN, columns)}), not counted")
        loss = CheckRow("contact_loss", "-", float(lifts), "passages", 0.0, np.nan, lost,
                        note=f"passages (of the {done} in the file) in which a wheel's contact force (its 10 ms mean) "
                             f"reaches zero (it lifts) on the bridge, {counted}{off}{held}{brief}"
                             f"{'; ' + unchecked if rings else ''}{lost_note}{free_end}")
        if lifts:
            t, v, s, i2 = _governing(results, np.where(lifting[..., None], -low, np.nan), np.nanargmax)
            loss.train, loss.speed_kmh, loss.seed = t, v, s
            loss.where = wheel_or_car_place(results, name, i2, MIN, columns, whole_run=False)
        return rows + [loss]
    return []
