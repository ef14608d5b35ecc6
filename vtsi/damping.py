"""Damping of a bridge model by a ratio: Rayleigh damping fitted to two frequencies, and the
bending frequencies it is fitted to.

With C = α M + β K a mode of frequency f has the damping ratio ζ(f) = α / (4π f) + π β f: equal
to ζ at the two fitting frequencies f_a < f_b, smaller between them (its minimum, at √(f_a f_b),
is 2ζ√(f_a f_b)/(f_a + f_b)), and growing without bound above f_b (β's share) and below f_a (α's).
Fitted through the first frequency n₀ and the EN 1990 A2 cut-off, every mode that counts gets
at most ζ (the lower bound of EN 1991-2 Table 6.6 is therefore not exceeded there) and the modes
above the cut-off are damped more. An exact ratio on every mode needs a modal model.

A bridge of several decks (simply supported spans on shared piers, decks between joints:
:mod:`vtsi.deck`, found along its track) has each deck's own n₀, n₂, n₃
(:func:`deck_frequencies`) and the largest of their cut-offs (:func:`decks_cutoff_hz`); the
model's first three frequencies would mix the decks' (two 15 m decks on one pier: 10.66, 10.66,
42.66 Hz, cut-off 42.66 Hz instead of each deck's 96.03 Hz). :func:`bridge_frequencies` reads
both as a sweep's passage does, and gives the defaults of :func:`rayleigh_damping` and of the
modal bridge's basis (:class:`~vtsi.modal_bridge.ModalBridge`).
"""
from dataclasses import dataclass

import numpy as np

from vtsi.analysis import lowest_modes_until
from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
from vtsi.deck import deck_layout
from vtsi.errors import ModelError, as_number, number_array
from vtsi.model import Model
from vtsi.track import Track


def vertical_frequencies(model, n=3, ground=()):
    """The first ``n`` (an integer >= 1) vertical (bending) natural frequencies [Hz] and mode
    shapes of a model: the modes whose mass-weighted uy motion exceeds their ux motion (a
    beam's axial modes are skipped) and, with ``ground`` (node tags: a track's stretches on the
    ground, :mod:`vtsi.deck`), whose vertical kinetic energy lies at most half at those nodes
    (a mode of an approach on springs is not the bridge's: it read a 20 m deck's n₃ = 74.5 Hz as
    the approach's 36.2 Hz). As many modes are computed as needed, at most one per dof with mass
    (lumped mass leaves rotations without). A ModelError says how many the model has if fewer
    than ``n``."""
    n = _count(n)
    modes = _VerticalModes(model, ground)
    lowest_modes_until(model, max(3 * n, 12), lambda *pair: np.count_nonzero(modes.read(*pair)) >= n)
    keep = np.flatnonzero(modes.bridge)[:n]
    if len(keep) < n:
        approach = int(np.sum(modes.vertical_share & ~modes.bridge))
        raise ModelError(f"vertical frequencies: {n} asked, the model has {len(keep)} vertical modes"
                         + (f" besides {approach} of its approaches" if approach else "") + modes.mass_hint())
    return modes.frequencies[keep], modes.shapes[:, keep]


def deck_frequencies(model, decks, n=3, ground=()):
    """``(n_decks, n)`` [Hz]: each deck's first ``n`` vertical frequencies (n₀, n₂, n₃ …), for
    ``decks`` the node tags of each deck (:attr:`vtsi.deck.DeckLayout.nodes_by_deck`) and
    ``ground`` as :func:`vertical_frequencies`.

    One deck: :func:`vertical_frequencies`'. Several: each vertical mode that is not an
    approach's (as there) counts for deck d by the share of its vertical kinetic energy on the
    deck's nodes, s_d = E_d / (E_vertical − E_ground); in ascending frequency, the deck's k-th
    frequency is that of the mode at which the running sum of s_d reaches k − ½. A mode on one
    deck counts 1 there and 0 on the others; two identical decks' equal frequencies make a
    degenerate pair, whose shapes an eigensolver may return combined in any proportion, and the
    running sum, the pair's trace, does not depend on how (a rule 'kept where it lies mostly'
    would count both of a 50/50 pair for each deck); a mode on no deck (a pier's) counts for
    none. Two identical simply supported 15 m decks on one pier: 10.66, 42.66, 96.03 Hz each,
    where the model's first three are 10.66, 10.66, 42.66. A ModelError names a deck with fewer
    than ``n``."""
    n = _count(n)
    decks = [list(nodes) for nodes in decks]
    if len(decks) == 1:
        return vertical_frequencies(model, n, ground)[0][None, :]
    modes = _VerticalModes(model, ground)

    def every_deck(omega2, shapes):
        modes.read(omega2, shapes)
        return all(len(modes.deck_frequencies(nodes, n)) == n for nodes in decks)
    lowest_modes_until(model, max(3 * n * len(decks), 12), every_deck)
    found = [modes.deck_frequencies(nodes, n) for nodes in decks]
    for d, f in enumerate(found):
        if len(f) < n:
            raise ModelError(f"vertical frequencies: {n} asked of deck {d + 1} of {len(decks)} (its track nodes "
                             f"{decks[d][0]} to {decks[d][-1]}), the model's vertical modes give it {len(f)}"
                             + modes.mass_hint())
    return np.array(found)


class _VerticalModes:
    """The lowest modes of a model with their vertical, horizontal and ground shares of kinetic
    energy (:func:`vertical_frequencies`, :func:`deck_frequencies`)."""

    def __init__(self, model, ground):
        if not isinstance(model, Model):
            raise ModelError(f"vertical frequencies: model must be a vtsi.Model, got {model!r}")
        self.asm = asm = model.build()
        self.on_ground = self.mask(ground)
        self.n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))   # at most that many modes of finite frequency
        if self.n_mass == 0:
            raise ModelError("vertical frequencies: no dof carries mass")

    def mask(self, nodes):
        """(n_full,) True at the uy dofs of ``nodes``."""
        out = np.zeros(self.asm.n_full, dtype=bool)
        for node in nodes:
            out[self.asm.full_dof(node, 2)] = True
        return out

    def energy(self, mask):
        """(n_modes,) each mode's φᵀ M φ over the dofs of ``mask`` (twice its kinetic energy there at ω = 1)."""
        part = self.shapes * mask[:, None]
        return np.einsum("ij,ij->j", part, self.asm.M_full @ part)

    def read(self, omega2, shapes):
        """Take the modes ``(omega2, shapes)`` of :func:`~vtsi.analysis.eigen` and return
        :attr:`bridge`: True for each vertical mode that is not an approach's."""
        asm = self.asm
        self.shapes = shapes
        self.frequencies = np.sqrt(np.maximum(omega2, 0.0)) / (2 * np.pi)
        dof = np.arange(asm.n_full) % asm.ndf
        self.vertical = self.energy(dof == 1)
        self.ground = self.energy(self.on_ground)
        self.vertical_share = self.vertical > self.energy(dof == 0)
        self.bridge = self.vertical_share & ~(self.ground > 0.5 * self.vertical)     # not an approach's
        return self.bridge

    def deck_frequencies(self, nodes, n):
        """The first (at most ``n``) frequencies of the deck of ``nodes`` (:func:`deck_frequencies`)."""
        keep = np.flatnonzero(self.bridge)
        with np.errstate(divide="ignore", invalid="ignore"):
            share = self.energy(self.mask(nodes))[keep] / (self.vertical - self.ground)[keep]
        running = np.cumsum(np.nan_to_num(np.clip(share, 0.0, 1.0)))
        at = np.searchsorted(running, np.arange(n) + 0.5 - 1e-9)       # the first mode reaching k - 1/2
        return self.frequencies[keep[at[at < len(keep)]]]

    def mass_hint(self):
        asm = self.asm
        return (f" (only {self.n_mass} of its {asm.n_free} free dofs carry mass: mesh the deck finer, or give it mass)"
                if self.n_mass < asm.n_free else "")


def _count(n):
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ModelError(f"vertical frequencies: the count must be an integer >= 1, got {n!r}")
    return n


def rayleigh_coefficients(zeta, f_a, f_b):
    """α [1/s], β [s] of C = α M + β K with damping ratio ``zeta`` [-] (in [0, 1)) at the
    distinct frequencies f_a and f_b [Hz] (> 0)."""
    zeta = _ratio(zeta)
    f_a, f_b = _frequencies((f_a, f_b))
    w_a, w_b = 2 * np.pi * f_a, 2 * np.pi * f_b
    return 2 * zeta * w_a * w_b / (w_a + w_b), 2 * zeta / (w_a + w_b)


def rayleigh_ratio(f, alpha, beta):
    """The damping ratio ζ(f) = α / (4π f) + π β f [-] that C = α M + β K gives a mode of
    frequency ``f`` [Hz] (> 0; see the module docstring); ``alpha`` [1/s] and ``beta`` [s] finite
    and >= 0, as :meth:`vtsi.Model.rayleigh` takes them."""
    hz = number_array(f)
    if hz is None:
        raise ModelError(f"rayleigh ratio: frequencies must be numbers [Hz], got {f!r}")
    alpha, beta = as_number(alpha, "rayleigh ratio", "alpha"), as_number(beta, "rayleigh ratio", "beta")
    if not (np.isfinite(alpha) and np.isfinite(beta) and alpha >= 0.0 and beta >= 0.0):
        raise ModelError(f"rayleigh ratio: alpha [1/s] and beta [s] must be finite and >= 0, got ({alpha:g}, {beta:g})")
    if not np.all(np.isfinite(hz) & (hz > 0.0)):
        raise ModelError(f"rayleigh ratio: frequencies must be > 0 and finite [Hz], got {hz.tolist()}")
    return alpha / (4 * np.pi * hz) + np.pi * beta * hz


def decks_cutoff_hz(deck_frequencies_hz):
    """The EN 1990 A2.4.4.2.1(4)P cut-off [Hz] of a bridge of one or more decks: the largest of
    its decks' max(30 Hz, 1.5 n₀, n₃) (:func:`~vtsi.codes.en1990_a2.acceleration_cutoff_hz`),
    ``deck_frequencies_hz`` (n_decks, 3) each deck's n₀, n₂, n₃ [Hz] (:func:`deck_frequencies`;
    a (3,) row: one deck). Counting every frequency up to the largest is on the safe side for
    each deck (the EN asks at least its own)."""
    rows = number_array(deck_frequencies_hz)
    if rows is None or rows.ndim not in (1, 2) or rows.shape[-1] != 3 or rows.size == 0:
        raise ModelError(f"EN 1990 A2.4.4.2.1: the cut-off of decks needs each deck's n0, n2, n3 [Hz], "
                         f"(n_decks, 3), got {deck_frequencies_hz!r}")
    return max(acceleration_cutoff_hz(f) for f in rows.reshape(-1, 3))


def deck_frequencies_table(record):
    """(n_decks, 3) each deck's n₀, n₂, n₃ [Hz] (:func:`deck_frequencies`) of a bridge record
    ``record``: a results file's /bridge (:meth:`SweepResults.bridge()
    <vtsi.sweep_results.SweepResults.bridge>`, every file of the format vtsi reads holds them)
    or :attr:`PassageRunner.frequency_record <vtsi.passage.PassageRunner.frequency_record>`.
    The one reading of the table: the cut-off, the check, the report and the speed grid call it."""
    return np.asarray(record["deck_frequencies_hz"], dtype=float).reshape(-1, 3)


def bridge_modes(model, frequencies, shapes, ground=()):
    """(n,) bool: which of the modes ``(frequencies (n,) [Hz], shapes (n_full, n))`` of ``model``
    are the bridge's vertical modes as :func:`vertical_frequencies` keeps them (more uy than ux
    motion, at most half their vertical kinetic energy at the ``ground`` nodes): a beam's axial
    modes and an approach's are not."""
    return _VerticalModes(model, ground).read((2 * np.pi * np.asarray(frequencies, dtype=float)) ** 2, shapes)


@dataclass(frozen=True)
class BridgeFrequencies:
    """A bridge's vertical frequencies as a sweep's passage reads them (:func:`bridge_frequencies`).

    first_hz : the bridge's first vertical frequency n₀ [Hz] (the modes of approaches on the
        ground left out): the lower anchor of the default Rayleigh damping.
    deck_hz : (n_decks, 3) each deck's n₀, n₂, n₃ [Hz] (:func:`deck_frequencies`).
    cutoff_hz : the EN cut-off [Hz], the largest of the decks' (:func:`decks_cutoff_hz`).
    """

    first_hz: float
    deck_hz: np.ndarray
    cutoff_hz: float


def bridge_frequencies(model, track=None):
    """The :class:`BridgeFrequencies` of ``model`` along ``track`` (a
    :class:`~vtsi.track.Track`, or the tags of its elements): its decks, their track nodes and
    the track's stretches on the ground by the rules of :func:`vtsi.deck.deck_layout`, each
    deck's n₀, n₂, n₃ by :func:`deck_frequencies`, as :class:`vtsi.passage.PassageRunner` reads
    them (the same numbers: its cut-off, Rayleigh anchors and modal basis).

    Without a track the decks cannot be found (they are read along it): the model is read as one
    deck, its first three vertical frequencies (approaches' modes included), right for a single
    deck; a bridge of several decks needs its track (else its cut-off reads the model's third
    frequency: 42.66 Hz for two 15 m decks on one pier, where each deck's is 96.03 Hz)."""
    if not isinstance(model, Model):
        raise ModelError(f"bridge frequencies: model must be a vtsi.Model, got {model!r}")
    if track is None:
        rows = vertical_frequencies(model, 3)[0][None, :]
        return BridgeFrequencies(float(rows[0, 0]), rows, decks_cutoff_hz(rows))
    layout = deck_layout(model, _track(model, track))
    rows = deck_frequencies(model, layout.nodes_by_deck, 3, ground=layout.ground_nodes)
    first = rows[0, 0] if len(rows) == 1 else vertical_frequencies(model, 1, ground=layout.ground_nodes)[0][0]
    return BridgeFrequencies(float(first), rows, decks_cutoff_hz(rows))


def _track(model, track):
    """``track`` as a :class:`~vtsi.track.Track` of ``model`` (given one, or its element tags)."""
    if isinstance(track, Track):
        return track
    if isinstance(track, (str, bytes)) or not np.iterable(track):
        raise ModelError(f"bridge frequencies: track must be a vtsi.track.Track or the tags of its elements, "
                         f"got {track!r}")
    return Track(model, list(track))


def rayleigh_damping(model, zeta, frequencies_hz=None, track=None):
    """Give ``model`` the damping ratio ``zeta`` [-] by Rayleigh damping through
    ``frequencies_hz`` = (f_a, f_b) [Hz], by default the bridge's first vertical frequency n₀ and
    the EN 1990 A2 cut-off max(30 Hz, 1.5 n₀, n₃), of several decks the largest of theirs, read
    along ``track`` (a :class:`~vtsi.track.Track` or its element tags) by
    :func:`bridge_frequencies`, as a sweep's passage reads them; without a track the model is
    read as one deck (:func:`bridge_frequencies`: give a bridge of several decks its track).
    ``track`` serves the default only: with ``frequencies_hz`` it is refused. Returns (α, β).

    The damping covers every element (``Model.rayleigh(..., every_element=True)``): the elements
    that OpenSees leaves out of Rayleigh damping by default (``zeroLength`` bearings and ``truss``
    members, ``do_rayleigh`` 0) are in it too, so that C = α M + β K of the whole model and every
    mode has exactly ζ(f) = α / (4π f) + π β f. Left out, a mode straining the bearings got less: a 25 + 32 + 25 m
    viaduct on zeroLength bearings (kv = 5 GN/m), ζ = 1 % through 6.31 and 30 Hz, had 0.58 %
    instead of 0.89 % at 24.51 Hz (non-classical damping), and its deck acceleration under
    HSLM-A2 at 334 km/h read 3.165 instead of 2.415 m/s² (tests/test_viaduct_fidelities.py).
    A script's own ``rayleigh`` keeps OpenSees' rule (:meth:`vtsi.Model.rayleigh`)."""
    if not isinstance(model, Model):
        raise ModelError(f"damping: model must be a vtsi.Model, got {model!r}")
    zeta = _ratio(zeta)
    if frequencies_hz is not None and track is not None:
        raise ModelError("damping: give frequencies_hz or track (whose bridge frequencies give the default), not both")
    if frequencies_hz is None:
        f = bridge_frequencies(model, track)
        frequencies_hz = (f.first_hz, f.cutoff_hz)
    alpha, beta = rayleigh_coefficients(zeta, *_frequencies(frequencies_hz))
    model.rayleigh(alpha, beta, every_element=True)
    return alpha, beta


def _ratio(zeta):
    """The damping ratio ``zeta`` as a float in [0, 1), or a ModelError naming the value."""
    zeta = as_number(zeta, "damping", "the ratio")
    if not 0.0 <= zeta < 1.0:
        raise ModelError(f"damping: the ratio must be in [0, 1) (0.01 for 1 %), got {zeta}")
    return zeta


def _frequencies(frequencies_hz):
    """Two distinct fitting frequencies (f_a, f_b) [Hz] > 0 and finite, or a ModelError naming them."""
    if isinstance(frequencies_hz, (str, bytes)) or np.ndim(frequencies_hz) != 1 or len(frequencies_hz) != 2:
        raise ModelError(f"damping: give two frequencies (f_a, f_b) [Hz], got {frequencies_hz!r}")
    f_a, f_b = (as_number(f, "damping", "a frequency [Hz]") for f in frequencies_hz)
    for f in (f_a, f_b):
        if not (np.isfinite(f) and f > 0.0):
            raise ModelError(f"damping: frequencies must be > 0 and finite [Hz], got ({f_a:g}, {f_b:g})")
    if f_a == f_b:
        raise ModelError(f"damping: the two frequencies must differ, got ({f_a:g}, {f_b:g})")
    return f_a, f_b
