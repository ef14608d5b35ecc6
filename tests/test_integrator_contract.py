"""Every registered integrator obeys the contract of :mod:`vtsi.integrators.base`.

Parametrised over ``vtsi.integrators.INTEGRATORS`` (each built with its defaults, HHT with the
α it requires), so a newly registered scheme is checked without editing this file. The properties that need a simulation or
the amplification matrix (order, spectral radius, stability limit) are in test_integrators.py.
"""
import numpy as np
import pytest

from vtsi.errors import AnalysisError
from vtsi.integrators import INTEGRATORS, Integrator, Stage, make_integrator, register

NAMES = sorted(INTEGRATORS)
STEPS = (1e-3, 0.37)


@pytest.fixture(params=NAMES)
def integrator(request, required_args):
    return INTEGRATORS[request.param](*required_args(request.param))


def test_registry_is_not_empty():
    assert {"Newmark", "HHT", "Bathe", "CentralDifference"} <= set(INTEGRATORS)


def test_class_attributes(integrator):
    """Item 1: ``name`` (the registry key) and ``n_stages``; ``n_slots = 3 + 3 n_stages``."""
    assert isinstance(integrator.name, str) and INTEGRATORS[integrator.name] is type(integrator)
    assert isinstance(integrator.n_stages, int) and integrator.n_stages >= 1
    assert integrator.n_slots == 3 + 3 * integrator.n_stages
    assert isinstance(integrator.explicit, bool)
    assert type(integrator).__name__ in repr(integrator)


@pytest.mark.parametrize("dt", STEPS)
def test_stages_have_the_declared_shape(integrator, dt):
    """Item 2: ``n_stages`` Stage objects, four float64 coefficient vectors of length
    ``n_slots + 1``, finite; stage end times increase to 1; load points in [0, 1] with weights
    summing to the equation's total mass coefficient ``1 + Σ km`` (a constant load balances a
    constant acceleration)."""
    stages = integrator.stages(dt)
    assert isinstance(stages, list) and len(stages) == integrator.n_stages
    thetas = []
    for st in stages:
        assert isinstance(st, Stage)
        for name in ("du", "dv", "ku", "kv", "km"):
            c = getattr(st, name)
            assert isinstance(c, np.ndarray) and c.dtype == np.float64 and c.shape == (integrator.n_slots + 1,)
            assert np.all(np.isfinite(c))
        assert st.km[-1] == 0.0
        assert len(st.load) >= 1
        assert all(0.0 <= theta <= 1.0 for theta, _ in st.load)
        assert sum(w for _, w in st.load) == pytest.approx(1.0 + st.km.sum(), rel=1e-14)
        thetas.append(st.theta)
    assert np.all(np.diff(thetas) > 0.0) and 0.0 < thetas[0] and thetas[-1] == 1.0


@pytest.mark.parametrize("dt", STEPS)
def test_force_weights(integrator, dt):
    """Item 6: ``mass_weight = 1 + Σ km`` (exactly 1.0 when km = 0, so that the schemes without
    km weight the train's constant load and the previous constraint forces as before) and
    ``force_weight > 0``; the built-in schemes interpolate the constraint forces, so also
    ``force_weight <= mass_weight`` (a user's Wilson-θ extrapolates: tests/test_user_integrators.py)."""
    for st in integrator.stages(dt):
        assert st.mass_weight == 1.0 + st.km.sum()
        if not np.any(st.km):
            assert st.mass_weight == 1.0
        assert 0.0 < st.force_weight <= st.mass_weight * (1.0 + 1e-14)


@pytest.mark.parametrize("dt", STEPS + (1e-6, 30.0))
def test_stages_pass_the_check_every_analysis_makes(integrator, dt):
    """Items 2, 4, 6, 8 as :meth:`Integrator.checked_stages` checks them when an analysis prepares
    a Δt (counts, shapes, slots, load and force weights, consistency): every registered scheme
    passes, at small and large steps, and the check leaves the stages as :meth:`stages` gives
    them."""
    checked = integrator.checked_stages(dt)
    for st, plain in zip(checked, integrator.stages(dt)):
        for name in ("du", "dv", "ku", "kv", "km"):
            assert np.array_equal(getattr(st, name), getattr(plain, name))
        assert (st.load, st.theta, st.force_weight) == (plain.load, plain.theta, plain.force_weight)


@pytest.mark.parametrize("dt", STEPS)
def test_a_stage_reads_only_earlier_slots(integrator, dt):
    """Item 2: stage ``s`` may read slots ``0 .. 2 + 3 s`` (the step start and earlier stages)
    and the unknown's column ``A``, nothing it has not written yet."""
    A = integrator.n_slots
    for s, st in enumerate(integrator.stages(dt)):
        for name in ("du", "dv", "ku", "kv", "km"):
            c = getattr(st, name)
            assert not np.any(c[3 + 3 * s: A]), f"stage {s + 1} {name} reads a later slot: {c}"


@pytest.mark.parametrize("dt", STEPS)
def test_effective_matrix_coefficients_are_non_negative(integrator, dt):
    """``K̂ = M + kv[A] C + ku[A] K`` stays positive definite for SPD M, C, K only if
    ``kv[A], ku[A] >= 0``."""
    A = integrator.n_slots
    for st in integrator.stages(dt):
        assert st.ku[A] >= 0.0 and st.kv[A] >= 0.0


def test_explicit_flag_matches_coefficients(integrator):
    """Item 4: ``explicit`` iff ``ku[A] = 0`` in every stage (no stiffness in ``K̂``)."""
    A = integrator.n_slots
    assert integrator.explicit == all(st.ku[A] == 0.0 for st in integrator.stages(0.01))


@pytest.mark.parametrize("dt", STEPS)
def test_constant_acceleration_is_integrated_exactly(integrator, dt):
    """Consistency: for ``ü = f`` (M = 1, K = C = 0, constant load f) every stage solves
    ``a_s + Σ km X = f Σ w``, i.e. ``a_s = f``, and must give ``u = u0 + v0 θΔt + f (θΔt)²/2``, ``v = v0 + f θΔt`` at its end
    time θΔt, to roundoff (1e-13 relative)."""
    u0, v0, f = 0.7, -1.3, 2.9
    n, A = integrator.n_slots, integrator.n_slots
    bank = np.zeros(n)
    bank[:3] = u0, v0, f
    for s, st in enumerate(integrator.stages(dt)):
        a = f * sum(w for _, w in st.load) - st.km[:A] @ bank
        u = st.du[:A] @ bank + st.du[A] * a
        v = st.dv[:A] @ bank + st.dv[A] * a
        h = st.theta * dt
        assert u == pytest.approx(u0 + v0 * h + 0.5 * f * h * h, rel=1e-13, abs=1e-15)
        assert v == pytest.approx(v0 + f * h, rel=1e-13, abs=1e-15)
        bank[3 + 3 * s: 6 + 3 * s] = u, v, a


def test_stability_limit_is_none_or_positive(integrator):
    """Item 3: None (unconditionally stable) or a positive finite ``ωΔt``, the same for any Δt
    (it is a bound on the product)."""
    limits = [integrator.stability_limit(dt) for dt in STEPS]
    if limits[0] is None:
        assert all(lim is None for lim in limits)
    else:
        assert np.isfinite(limits[0]) and limits[0] > 0.0
        assert limits == pytest.approx([limits[0]] * len(limits), rel=1e-14)


def test_stages_are_fresh_objects(integrator):
    """Changing a returned Stage must not change the integrator (callers may adapt them)."""
    first = integrator.stages(0.1)
    first[0].du[:] = np.nan
    first[0].load.append((0.5, 0.0))
    second = integrator.stages(0.1)
    assert np.all(np.isfinite(second[0].du)) and (0.5, 0.0) not in second[0].load


def test_selection_by_name_class_and_instance(required_args):
    for name, cls in INTEGRATORS.items():
        args = required_args(name)
        assert type(make_integrator(name, *args)) is cls
        assert type(make_integrator(cls, *args)) is cls
        instance = cls(*args)
        assert make_integrator(instance) is instance
        if args:
            with pytest.raises(AnalysisError, match="give"):
                make_integrator(name)
    with pytest.raises(AnalysisError, match="known: " + ", ".join(sorted(INTEGRATORS))):
        make_integrator("NoSuchScheme")


def test_register_refuses_a_name_registered_by_another_class():
    """Item 7 (as the element registry): a second class under a registered name is refused."""
    for name, cls in INTEGRATORS.items():
        clash = type("Clash", (cls,), {"name": name})
        with pytest.raises(TypeError, match=f"integrator name '{name}' of .*Clash is already registered by "
                                            f"{cls.__module__}.{cls.__qualname__}"):
            register(clash)
        assert INTEGRATORS[name] is cls


def test_register_requires_name_and_stages():
    class Nameless(Integrator):
        n_stages = 1

    class Stageless(Integrator):
        name = "stageless-test"

    for cls in (Nameless, Stageless):
        with pytest.raises(TypeError, match="missing class attribute"):
            register(cls)
    assert "stageless-test" not in INTEGRATORS


def test_dissipative_is_read_from_the_stages_not_the_class():
    """``dissipative`` (the spectral radius below 1 at the highest Ω a scheme steps) flags the
    trapezoidal rule whatever its class: a user's scheme that is not a Newmark subclass but steps
    as Newmark's γ = ½ rule is refused with contact='lcp', as Newmark() is (the class test it
    replaces let it through)."""
    from vtsi.coupled import coupled_integrator
    from vtsi.integrators import HHT, Bathe, CentralDifference, Newmark

    class Trapezoid(Integrator):            # not registered: an instance is passed
        name, n_stages = "trapezoid-test", 1

        def stages(self, dt):
            return Newmark(0.5, 0.25).stages(dt)

    flags = {repr(i): i.dissipative for i in (Newmark(), HHT(1.0), CentralDifference(), Trapezoid(),
                                               HHT(0.9), Newmark(0.6, 0.3025), Bathe())}
    assert list(flags.values()) == [False] * 4 + [True] * 3, flags
    assert HHT(0.9).spectral_radius(1e4) == pytest.approx((1 - 0.1) / (1 + 0.1), rel=1e-6)   # ρ∞ = (1 − a)/(1 + a), a = 1 − α
    for scheme in (Trapezoid(), Newmark()):
        with pytest.raises(AnalysisError, match="contact='lcp' needs a dissipative integrator"):
            coupled_integrator(scheme, "lcp")
    assert coupled_integrator(HHT(0.9), "lcp").dissipative
