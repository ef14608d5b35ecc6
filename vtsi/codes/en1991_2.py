"""EN 1991-2:2003 (traffic loads on bridges), §6.4.6: rules for the dynamic analysis of railway
bridges.

Units: spans L [m]; damping ratios as fractions (0.01 for 1 %), not percent.
"""
import numpy as np

from vtsi.errors import ModelError, as_number, as_numbers, as_positive

# Table 6.6, lower limits of the damping ratio ζ [%] for span L [m]: (value for L >= 20 m, slope
# per metre below 20 m).
DAMPING_TABLE_6_6 = {
    "steel": (0.5, 0.125), "composite": (0.5, 0.125),
    "prestressed_concrete": (1.0, 0.07),
    "filler_beam": (1.5, 0.07), "reinforced_concrete": (1.5, 0.07),
}
ADDITIONAL_DAMPING_SPANS = (0.0, 30.0)   # [m] range of Eq. 6.13 (Figure 6.15)
HSLM_B_SPAN_RANGE = (1.0, 7.0)          # [m] spans L_min <= L < L_max loaded by HSLM-B (§6.4.6.1.1, Fig. 6.13)
HSLM_A = tuple(f"HSLM-A{k}" for k in range(1, 11))   # the ten universal trains of Table 6.3
HSLM_B = "HSLM-B"
SPEED_SERIES_START_KMH = 144.0          # [km/h] 40 m/s: the series of speeds starts there (§6.4.6.2(3))


def hslm_b_refusal(decks):
    """Why HSLM-B does not load a bridge of ``decks`` (each deck's span lengths [m], x order),
    in one line, or '' when it does: EN 1991-2 6.4.6.1.1 and Table 6.4 load a simply supported
    span of L_min <= L < L_max (:data:`HSLM_B_SPAN_RANGE`) with HSLM-B, its N and d from that L
    (Figure 6.13), and a continuous deck with HSLM-A1 to A10. A bridge takes HSLM-B when every
    deck is one span and all are of one length in that range (each deck then takes that L's)."""
    decks = [as_numbers(spans, "EN 1991-2 6.4.6.1.1", "a deck's spans [m]").ravel().tolist() for spans in decks]
    lo, hi = HSLM_B_SPAN_RANGE
    rule = (f"HSLM-B loads simply supported spans of {lo:g} m <= L < {hi:g} m only, each with the N and d of its "
            "L (EN 1991-2 6.4.6.1.1, Table 6.4)")
    if not decks or not all(decks):
        return f"{rule}: the bridge has a deck without a span"

    def deck(k):
        return "the deck" if len(decks) == 1 else f"deck {k + 1}"
    continuous = next((k for k, spans in enumerate(decks) if len(spans) > 1), None)
    if continuous is not None:
        return (f"{rule}: {deck(continuous)} is continuous (spans {' + '.join(f'{L:g}' for L in decks[continuous])} "
                "m); take HSLM-A1 to A10 (--trains HSLM-A), as Table 6.4 asks of a continuous deck")
    spans = [spans[0] for spans in decks]
    outside = next((k for k, L in enumerate(spans) if not lo <= L < hi), None)
    if outside is not None:
        others = (f"; check the decks under {hi:g} m as bridges of their own with HSLM-B"
                  if any(lo <= L < hi for L in spans) else "")
        return (f"{rule}: the span of {deck(outside)} is {spans[outside]:g} m; take HSLM-A1 to A10 (--trains "
                f"HSLM-A), or the critical ones of Annex E for a simply supported span{others}")
    if not np.allclose(spans, spans[0], rtol=1e-9, atol=0.0):
        return (f"{rule}: the decks' spans differ ({', '.join(f'{L:g}' for L in spans)} m) and a sweep runs one "
                "HSLM-B; check each deck as a bridge of its own")
    return ""


def hslm_load_models(decks):
    """The HSLM trains EN 1991-2 6.4.6.1.1, Table 6.4 loads each of ``decks`` with (each deck's
    span lengths [m], x order), one tuple per deck: (HSLM_B,) for a simply supported span of
    L_min <= L < L_max (:data:`HSLM_B_SPAN_RANGE`), else :data:`HSLM_A`, all ten: a continuous
    deck takes them all; a simply supported span of 7 m or more may take a single critical one
    chosen by Annex E instead, a choice vtsi does not make, so no subset is shown to be enough."""
    decks = [as_numbers(spans, "EN 1991-2 Table 6.4", "a deck's spans [m]").ravel().tolist() for spans in decks]
    lo, hi = HSLM_B_SPAN_RANGE
    return [(HSLM_B,) if len(spans) == 1 and lo <= spans[0] < hi else HSLM_A for spans in decks]


def damping_lower_bound(kind, span):
    """EN 1991-2 Table 6.6: the lower bound of the damping ratio [-] of a ``kind`` bridge
    ('steel', 'composite', 'prestressed_concrete', 'filler_beam', 'reinforced_concrete') of span
    ``span`` [m]: ζ = ζ₂₀ + slope·(20 − L) [%] for L < 20 m, ζ₂₀ for L >= 20 m."""
    if not isinstance(kind, str) or kind not in DAMPING_TABLE_6_6:
        raise ModelError(f"EN 1991-2 Table 6.6: unknown bridge type {kind!r}; valid: {', '.join(DAMPING_TABLE_6_6)}")
    L = _span(span, "Table 6.6")
    base, slope = DAMPING_TABLE_6_6[kind]
    return (base + slope * max(20.0 - L, 0.0)) / 100.0


def additional_damping(span):
    """EN 1991-2 Eq. 6.13: the additional damping Δζ [-] that a moving-force analysis (no
    vehicle-bridge interaction) may add for span ``span`` [m]:
    Δζ = (0.0187 L − 0.00064 L²) / (1 − 0.0441 L − 0.0044 L² + 0.000255 L³) [%] for L < 30 m
    (largest, about 0.65 %, near L = 15 m). The numerator vanishes at L = 29.2 m; the slightly
    negative values of the formula between there and 30 m are returned as 0, and so is every
    L >= 30 m: 6.4.6.3.1(3) and Figure 6.15 give the interaction's extra damping to spans below
    30 m only (:func:`additional_damping_text` says which)."""
    L = _span(span, "Eq. 6.13")
    if not L < ADDITIONAL_DAMPING_SPANS[1]:
        return 0.0
    value = (0.0187 * L - 0.00064 * L ** 2) / (1.0 - 0.0441 * L - 0.0044 * L ** 2 + 0.000255 * L ** 3) / 100.0
    return max(value, 0.0)


def additional_damping_text(span):
    """Δζ of :func:`additional_damping` for span ``span`` [m] in words, as a damping source
    states it: 'Eq. 6.13 Δζ 0.296 %', or 'Δζ = 0 (EN 1991-2 Eq. 6.13: L ≥ 30 m)'."""
    L = _span(span, "Eq. 6.13")
    if not L < ADDITIONAL_DAMPING_SPANS[1]:
        return f"Δζ = 0 (EN 1991-2 Eq. 6.13: L ≥ {ADDITIONAL_DAMPING_SPANS[1]:g} m)"
    return f"Eq. 6.13 Δζ {100 * additional_damping(L):.3g} %"


def _span(span, clause):
    return as_positive(span, f"EN 1991-2 {clause}", "span [m]")


FREQUENCY_SPANS = (4.0, 100.0)   # [m] the span range of Figure 6.10


def frequency_limits(span):
    """EN 1991-2 Figure 6.10: the lower and upper limits [Hz] of the first bending frequency n₀ of
    a span of ``span`` [m] inside which the simplified rules of 6.4.4 may apply: lower 80 / L for
    L <= 20 m, 23.58 L^-0.592 above; upper 94.76 L^-0.748 (the figure covers 4 to 100 m; a span
    outside is taken at its nearest end, for a plausibility floor: :func:`frequency_limits_text`
    says instead that the figure does not cover it)."""
    L = min(max(_span(span, "Figure 6.10"), FREQUENCY_SPANS[0]), FREQUENCY_SPANS[1])
    return (80.0 / L if L <= 20.0 else 23.58 * L ** -0.592), 94.76 * L ** -0.748


def frequency_limits_text(n0, spans):
    """EN 1991-2 Figure 6.10 read for one deck, in words (information: no verdict reads it):
    ``n0`` [Hz] the deck's first bending frequency, ``spans`` its span lengths [m]. L is the span
    of a simply supported deck and L_Φ (:func:`determinant_length`) of a continuous one, as 6.4.4
    takes it for other bridges. The text gives n₀, the limits at L and where n₀ lies; outside
    them Figure 6.9 asks for a dynamic analysis, inside them its other tests (the line speed, the
    structure, Annex F) decide, which the check does not read. An L outside 4 to 100 m is said to
    lie outside the figure, which gives it no limits."""
    where = "EN 1991-2 Figure 6.10"
    n0 = as_positive(n0, where, "n0 [Hz]")
    spans = [_span(s, "Figure 6.10") for s in as_numbers(spans, where, "a deck's spans [m]").ravel()]
    L = determinant_length(spans)
    simple = len(spans) == 1
    deck = f"the {spans[0]:g} m span" if simple else f"the {' + '.join(f'{s:g}' for s in spans)} m continuous deck"
    at = f"L = {L:.4g} m ({'the span' if simple else 'its L_Phi, 6.4.4'})"
    if not FREQUENCY_SPANS[0] <= L <= FREQUENCY_SPANS[1]:
        return (f"n0 {n0:.4g} Hz of {deck}: Figure 6.10 covers L = {FREQUENCY_SPANS[0]:g} to "
                f"{FREQUENCY_SPANS[1]:g} m, not {at}, and gives it no limits")
    lower, upper = frequency_limits(L)
    place = "within" if lower <= n0 <= upper else "below" if n0 < lower else "above"
    reading = ("Figure 6.9's other tests (line speed, structure, Annex F) decide whether a dynamic analysis is "
               "needed" if place == "within" else "outside them Figure 6.9 asks for a dynamic analysis")
    return f"n0 {n0:.4g} Hz of {deck} is {place} the limits, {lower:.4g} to {upper:.4g} Hz at {at}: {reading}"


# Table 6.2, case 5.2: L_Φ = k × mean span of a continuous beam of n spans.
CONTINUOUS_K = {2: 1.2, 3: 1.3, 4: 1.4}
CONTINUOUS_K_MANY = 1.5


def determinant_length(spans):
    """L_Φ [m], EN 1991-2 Table 6.2: the span of a simply supported deck (case 5.1); k times the
    mean span of a continuous deck of n spans (case 5.2: k = 1.2, 1.3, 1.4, 1.5 for n = 2, 3, 4,
    ≥ 5), but not less than its longest span."""
    spans = [_span(s, "Table 6.2") for s in np.atleast_1d(np.asarray(spans, dtype=object))]
    if not spans:
        raise ModelError("EN 1991-2 Table 6.2: the determinant length needs at least one span [m], got none")
    if len(spans) == 1:
        return spans[0]
    return max(CONTINUOUS_K.get(len(spans), CONTINUOUS_K_MANY) * float(np.mean(spans)), max(spans))


def dynamic_factor(L_phi, maintenance="careful"):
    """Φ₂ (carefully maintained track) or Φ₃ (standard maintenance), EN 1991-2 §6.4.5.2:
    Φ₂ = 1.44 / (√L_Φ − 0.2) + 0.82 in [1.00, 1.67]; Φ₃ = 2.16 / (√L_Φ − 0.2) + 0.73 in [1.00, 2.00].
    The formulas grow without bound as L_Φ falls to 0.04 m: there, and below, Φ is the upper limit."""
    L = _span(L_phi, "6.4.5.2")
    root = np.sqrt(L) - 0.2
    if maintenance == "careful":
        return 1.67 if root <= 0.0 else float(np.clip(1.44 / root + 0.82, 1.0, 1.67))
    if maintenance == "standard":
        return 2.0 if root <= 0.0 else float(np.clip(2.16 / root + 0.73, 1.0, 2.0))
    raise ModelError(f"EN 1991-2 6.4.5.2: track maintenance must be 'careful' (Φ2) or 'standard' (Φ3), got {maintenance!r}")


def track_irregularity_increment(L_phi, n0, speed):
    """φ'' of EN 1991-2 Annex C(3) [-]: α/100 [56 e^(−(L_Φ/10)²) + 50 (L_Φ n₀/80 − 1) e^(−(L_Φ/20)²)],
    at least 0, with α = v/22 for v ≤ 22 m/s and 1 above (L_Φ [m], n₀ [Hz], v [m/s]). The dynamic
    analysis adds φ''/2 for carefully maintained track, φ'' for standard maintenance."""
    L = _span(L_phi, "Annex C")
    n0 = as_number(n0, "EN 1991-2 Annex C", "n0 [Hz]") if np.ndim(n0) == 0 else n0
    speed = as_number(speed, "EN 1991-2 Annex C", "speed [m/s]") if np.ndim(speed) == 0 else speed
    if not (np.ndim(n0) == 0 and np.ndim(speed) == 0 and np.isfinite(n0) and n0 > 0 and np.isfinite(speed)
            and speed > 0):
        raise ModelError(f"EN 1991-2 Annex C: n0 [Hz] and speed [m/s] must be > 0, got {n0!r}, {speed!r}")
    a = min(speed / 22.0, 1.0)
    value = a / 100.0 * (56.0 * np.exp(-(L / 10.0) ** 2) + 50.0 * (L * n0 / 80.0 - 1.0) * np.exp(-(L / 20.0) ** 2))
    return float(max(value, 0.0))
