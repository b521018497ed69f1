"""A guard that stops a run whose motion reaches or steps across a pole of its equations of motion.

The equations of motion of ``L = q_dot^T M(q, t) q_dot / 2 - V(q, t)`` with holonomic
constraints ``chi(q, t) = 0`` and generalized forces ``Q(q, q_dot, t)`` evaluate the force
``-dV/dq``, the entries of ``M`` and their derivatives, the constraints' first and second
derivatives and ``Q``. Where a denominator of these expressions vanishes (``x = 0`` of the
force ``-1/x`` of ``V = log(x)``; ``cos(q) = 0`` of ``V = tan(q)``; ``x - a = 0`` of a force
``1/(x - a)``) the vector field has a pole. Such a pole is a singularity of the physics, not
of the chart (Arnold, "Mathematical Methods of Classical Mechanics", Sect. 4 on motion in
a potential: with ``v^2/2 + V(x) = E`` the speed is infinite where ``V -> -infinity``, and
the motion reaches that point at a finite time when ``integral dx / sqrt(2 (E - V(x)))``
converges there). A fixed step is blind to it: the force ``-1/x`` is defined on both sides
of ``x = 0``, so a step jumps over the pole and the run goes on with an energy that jumped
(``V = log(x)`` from ``x = 0.5`` at rest with ``dt = 0.01``: a relative energy jump of 1.5,
and no word). A smaller step only moves the jump.

:class:`PoleGuard` evaluates the irreducible factors ``f`` of those denominators that can
vanish (:func:`dirac.analysis.core.divisors.denominator_factors`), compiled as one scalar
function of the coordinates (and the time). The loop of :func:`dirac.flows.integrate`
reads it between calls of the step loop and stops with :class:`~dirac.errors.PoleError`
when a factor is zero, or when its sign differs from the last reading: the motion stepped
across ``f = 0`` between the two readings, even if no reading came near it. The readings
come at every sample (before the sample is stored, so the partial run ends before the
crossing) and, in between, after half the steps in which the factor that falls fastest
would reach zero at its last rate, unless its approach slows down so as to stop before the
pole (:meth:`PoleGuard.next_reading`): every step next to a pole, up to
:data:`~dirac.flows.chart_guard.MAX_GUARD_STEPS` far away. A factor predicted at one reading
to reach zero before the next that went back instead stops the run too: the steps do not
resolve the motion at the pole (a composition's stages jumped over it and back, or a step
landed next to a repelling pole and was thrown back: ``V = c/x`` at ``dt = 0.01`` finished
with 1000 times its energy). A factor that changes its sign and back between two readings
farther apart is not seen (the readings' spacing makes that unlikely, not impossible). A factor of a
denominator is read only where the expression grows toward its zero set (:func:`_unbounded_at`):
``sin(x)/x`` is bounded at ``x = 0`` and the motion passes there. Factors that depend on the velocities (a force
``-c x_dot/|x_dot|``) are not read. Systems whose expressions hold no denominator (and no
function whose derivative has one: only sums, products, positive integer powers, ``sin``,
``cos`` and ``exp``) have no guard and run exactly as before, without a symbolic
derivative taken.

An analysed system (:class:`~dirac.flows.analysed.AnalysedSystem`, the flow on the whole phase
space) has the same guard over its state ``z`` (:func:`analysed_pole_guard`): the factors of the
denominators of ``grad H``, of the second-class constraints' gradients and of their time
derivatives, momenta and multipliers included. When an implicit step fails (its Newton
iteration) the run stops at the pole if the factor that falls fastest would reach zero within
:data:`READINGS_PER_APPROACH` steps at the rate of the last interval, or if it falls as
``(t* - t)^COLLAPSE_EXPONENT`` through the last two readings (that rate is a secant, which lags a
fall that speeds up); a failed step cannot tell a fall into the pole from a close pass that a
smaller step resolves, so that message says both.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from dirac.flows.chart_guard import GUARD_STEPS, MAX_GUARD_STEPS, built_once

__all__ = ["PoleGuard", "pole_guard", "analysed_pole_guard", "PoleCrossing", "message", "barrier_before",
           "READINGS_PER_APPROACH", "COLLAPSE_EXPONENT", "REMEDY"]

#: readings per predicted approach: the guard is read again after half the steps the fastest-falling factor
#: needs to reach zero at its last rate (the rate grows near an attracting pole: ``x ~ (t* - t)^(2/3)`` for
#: ``V = -1/x``, so the linear prediction is too late by a factor 3/2, and half of it comes before the pole)
READINGS_PER_APPROACH = 2

#: exponent ``a`` of the fastest approach to a pole that a failed step is judged by, ``f ~ (t* - t)^a``: the fall
#: into an attracting ``1/r`` pole (Kepler's collision orbit: ``r^(3/2) ~ t* - t``) and into ``V = tan(q)`` at
#: ``cos(q) = 0``; a logarithmic well comes in about linearly (``a`` near 1)
COLLAPSE_EXPONENT = 2.0 / 3.0

REMEDY = (
    "a smaller step does not cure this: the motion reaches a singularity of its equations (the potential, the "
    "mass matrix, the constraints or the forces are infinite there) at a finite time; regularise the expression "
    "near the pole (soften 1/x to x/(x**2 + eps**2), or log(x) to log(x**2 + eps**2)/2), stop the run before "
    "it (a t_end before the time named), or change the model (a wall: an impulse reversing the velocity)"
)


class PoleCrossing(Exception):
    """A reading of the guard found a factor at zero or across it (internal; the loop makes a PoleError of it).

    ``turn`` is true when the motion may turn before the pole, so that a smaller step would
    resolve it: the factor kept its sign but came within a step of zero and went back, or its
    approach was slowing down (a repelling pole that a step overshot).
    """

    def __init__(self, text: str, turn: bool = False) -> None:
        super().__init__(text)
        self.turn = turn


class PoleGuard:
    """The sign of each factor of the denominators of one system's equations of motion, compiled (module docstring).

    Attributes
    ----------
    factors
        The factors as text (``"x"``), in reading order.
    origins
        For each factor, what it is a denominator of (``"the force -dV/dq"``).
    """

    def __init__(self, values: Callable[..., list[float]], factors: list[str], origins: list[str], time: bool,
                 params: np.ndarray, bounds: list[bool] | None = None) -> None:
        self._values = values  # (f_1, f_2, ...)
        self.factors = factors
        self.origins = origins
        #: the factors as sympy expressions in the coordinates, the time and the parameters (symbolic)
        self.expressions: list[Any] = []
        #: for each factor, whether it also bounds the real domain (``x`` of ``log(x)``, ``sqrt(x)``)
        self.bounds = list(bounds) if bounds is not None else [False] * len(factors)
        self._time = time
        self._params = tuple(float(c) for c in params)
        #: the stepper's attribute the guard reads: the configuration ``q`` of a mechanical system, the whole
        #: state ``z`` of an analysed one
        self.state = "q"
        self._members = 1
        # the state of the readings, flat lists over (member, factor), plain floats: a reading of one
        # member costs a few microseconds (numpy's overhead on arrays this small would be ten times that)
        self._last: list[float] | None = None  # the last reading
        self._last_time = 0.0
        self._last_step = 0
        #: the state at the last reading (a copy), the start of the chord :func:`barrier_before` samples
        self.last_state: np.ndarray | None = None
        self._rate: list[float] = []  # approach per step of each factor over the last interval
        self._eta: list[float] = []  # steps to zero of each factor at that rate (inf: not approaching)
        self._accelerating: list[bool] = []  # whether that approach was as fast as the one before
        self._span = GUARD_STEPS  # steps of the last interval
        self._planned = GUARD_STEPS  # steps planned until the next reading
        #: steps in which the factor that falls fastest reaches zero at the rate of the last interval (inf: none falls)
        self.steps_to_pole = math.inf
        self._nearest = (0, 0, math.nan)
        #: steps in which a factor reaches zero if it falls as ``(t* - t)^COLLAPSE_EXPONENT`` (inf: none falls)
        self.steps_to_collapse = math.inf
        self._collapsing = (0, 0, math.nan)

    def _flat(self, q: np.ndarray, t: float) -> list[float]:
        """The factors' values at a batch of configurations, flat over (member, factor); NaN where undefined."""
        rows = q.tolist() if isinstance(q, np.ndarray) else list(q)
        if rows and not isinstance(rows[0], list):
            rows = [rows]
        self._members = len(rows)
        extra = (float(t),) if self._time else ()
        params = self._params
        values = self._values
        return [float(v) for row in rows for v in values(*row, *extra, *params)]

    def read(self, q: np.ndarray, t: float = 0.0) -> np.ndarray:
        """The factors' values at a batch of configurations ``q`` (shape ``(n,)`` or ``(B, n)``): ``(B, factors)``;
        NaN where a factor has no real value."""
        flat = self._flat(q, t)
        return np.array(flat, dtype=float).reshape(self._members, len(self.factors))

    def start(self, q: np.ndarray, t: float = 0.0, step: int = 0) -> None:
        """The first reading (at the initial state): the signs later readings are compared with.

        Raises
        ------
        PoleCrossing
            The initial state is on a pole (a factor is zero there).
        """
        self._last = self.last_state = None
        self.steps_to_pole = self.steps_to_collapse = math.inf
        self.check(q, t, step, GUARD_STEPS)

    def check(self, q: np.ndarray, t: float, step: int, steps: int, at: float | None = None) -> int:
        """Read the guard after ``steps`` steps that ended at time ``t`` (step ``step``); the steps until the next reading.

        ``t`` is the time the factors are evaluated at (that of the state); ``at``, when given,
        the time the messages name (the loop's time on the sample grid).

        Raises
        ------
        PoleCrossing
            A factor is zero, or its sign differs from that of the last reading (the motion
            stepped across the pole between them); its message names the factor, the member
            of a batch, the values and the interval of time. Also when a factor came within a
            step of zero, faster and faster, and went back (the steps jumped over the pole and
            back, or do not resolve a turn next to it).
        """
        now = self._flat(q, t)
        t = t if at is None else float(at)
        last = self._last
        if last is None or len(last) != len(now):
            for i, f in enumerate(now):
                if f == 0.0:
                    raise PoleCrossing(self._describe(i, now, None, t, step))
            # the first reading: every factor nonzero; NaN (no real value) is left to the loop's own checks
            self._last, self._last_time, self._last_step = now, t, step
            self.last_state = np.array(q, dtype=float)
            self._rate = [math.nan] * len(now)
            self._eta = [math.inf] * len(now)
            self._accelerating = [True] * len(now)
            self._span = self._planned = GUARD_STEPS
            return GUARD_STEPS
        span = max(steps, 1)
        mean_span = 0.5 * (span + self._span)
        rates, etas, accelerating = [], [], []
        collapse, collapsing = math.inf, -1
        for i, (f, g) in enumerate(zip(now, last)):
            if f == 0.0 or (f > 0.0 and g < 0.0) or (f < 0.0 and g > 0.0):  # at the pole, or across it
                # an approach that was slowing down may be a repelling pole the step overshot: hedged
                raise PoleCrossing(self._describe(i, now, last, t, step), turn=not self._accelerating[i])
            a, b = abs(g), abs(f)
            rate = (a - b) / span  # approach per step (positive: nearer to the pole); NaN where undefined
            if b > a and self._eta[i] <= steps:  # predicted to reach the pole in this interval, and went back
                raise PoleCrossing(self._describe_turn(i, now, last, t, step), turn=True)
            change = (rate - self._rate[i]) / mean_span  # of the approach rate, per step (NaN: no rate before)
            # an approach slowing down so that it stops within half the distance left turns before the pole
            # (a bound orbit's near pass, an oscillation): not a pole to watch step by step
            turns = change < 0.0 and rate * rate < -change * b
            rates.append(rate)
            etas.append(b / rate if rate > 0.0 and not turns else math.inf)
            accelerating.append(not change < 0.0)
            if rate > 0.0 and b > 0.0:  # f ~ (t* - t)^a through both readings: t* - t = span / ((a/b)^(1/a) - 1)
                left = span / max((a / b) ** (1.0 / COLLAPSE_EXPONENT) - 1.0, 1e-300)
                if left < collapse:
                    collapse, collapsing = left, i
        self._rate, self._eta, self._accelerating, self._span = rates, etas, accelerating, span
        self.steps_to_collapse = collapse
        if collapsing >= 0:
            self._collapsing = (collapsing // len(self.factors), collapsing % len(self.factors), now[collapsing])
        self._last, self._last_time, self._last_step = now, t, step
        self.last_state = np.array(q, dtype=float)
        return self.next_reading(now, span)

    def next_reading(self, now: list[float], steps: int) -> int:
        """Steps until the next reading, after ``steps`` steps that ended with the factors at ``now`` (flat).

        Each factor that came nearer to zero, and not more and more slowly so as to stop
        before it, would reach zero after ``|f| / rate`` more steps at the rate of the last
        interval; the guard is read again after ``1/READINGS_PER_APPROACH`` of the smallest
        such count (every step next to a pole), at most twice the interval planned before
        (or done) and :data:`MAX_GUARD_STEPS`.
        """
        limit = min(MAX_GUARD_STEPS, 2 * max(steps, self._planned, GUARD_STEPS // 2))
        to_zero = min(self._eta, default=math.inf)
        self.steps_to_pole = to_zero
        if to_zero == math.inf:
            self._planned = limit
            return limit
        i = self._eta.index(to_zero)
        self._nearest = (i // len(self.factors), i % len(self.factors), now[i])
        self._planned = max(1, min(limit, int(to_zero / READINGS_PER_APPROACH)))
        return self._planned

    def nearest_accelerating(self) -> bool:
        """Whether the approach of the factor that fell fastest at the last reading was speeding up."""
        member, k, _ = self._nearest
        return self._accelerating[member * len(self.factors) + k]

    def nearest(self, collapsing: bool = False) -> str:
        """The factor that fell fastest towards zero at the last reading (``collapsing``: the one a fall as a power
        :data:`COLLAPSE_EXPONENT` of the time left brings to zero first), its value and what it is a denominator of."""
        member, k, value = self._collapsing if collapsing else self._nearest
        who = f" of member {member}" if self._members > 1 else ""
        return f"{self.factors[k]} = {value:.3g}{who}, a denominator of {self.origins[k]}"

    def _who(self, i: int) -> tuple[str, int]:
        """`` (member m of the batch)`` (or nothing) and the factor's index, of the flat index ``i``."""
        member, k = divmod(i, len(self.factors))
        return (f" (member {member} of the batch)" if self._members > 1 else ""), k

    def _describe_turn(self, i: int, now: list[float], last: list[float], t: float, step: int) -> str:
        who, k = self._who(i)
        factor, origin = self.factors[k], self.origins[k]
        how = ", faster and faster," if self._accelerating[i] else ""
        return (f"the motion{who} came within a step of the pole {factor} = 0 of the equations of motion (a "
                f"denominator of {origin}){how} and was back at {factor} = {now[i]:.3g} "
                f"after {factor} = {last[i]:.3g}, between t = {self._last_time:.6g} and t = {t:.6g} (steps "
                f"{self._last_step} to {step}): the steps do not resolve the motion at the pole (they may have jumped "
                "over it and back, as the stages of a composition method can)")

    def _describe(self, i: int, now: list[float], last: list[float] | None, t: float, step: int) -> str:
        who, k = self._who(i)
        factor, origin = self.factors[k], self.origins[k]
        if last is None:
            return (f"the initial state{who} is on a pole of the equations of motion, {factor} = 0 (a denominator of "
                    f"{origin}); start away from it")
        before, value = last[i], now[i]
        if value == 0.0:
            what = f"reached the pole {factor} = 0 ({factor} was {before:.3g} at the reading before)"
        else:
            what = (f"stepped across the pole {factor} = 0 ({factor} went from {before:.3g} to {value:.3g}: "
                    "the step jumped over it, so the run after it is not the motion")
            if self.bounds[k]:
                what += (f"; {factor} = 0 also bounds the real domain of the system's expressions (a logarithm or a "
                         "root of it), so the run left the real domain there")
            what += ")"
        return (f"the motion{who} {what}, a pole of the equations of motion (a denominator of {origin}), between "
                f"t = {self._last_time:.6g} and t = {t:.6g} (steps {self._last_step} to {step})")


def _nodes(expr: Any) -> Any:
    import sympy

    return sympy.preorder_traversal(expr)


def _may_have_poles(exprs: list[Any]) -> bool:
    """Whether an expression or one of its derivatives can have a denominator: a power that is not a
    nonnegative integer, or a function other than ``sin``, ``cos`` and ``exp`` (whose derivatives have none)."""
    import sympy

    plain = (sympy.sin, sympy.cos, sympy.exp)
    for expr in exprs:
        for node in _nodes(expr):
            if isinstance(node, sympy.Pow) and not (node.exp.is_Integer and node.exp >= 0):
                return True
            if isinstance(node, sympy.Function) and not isinstance(node, plain):
                return True
    return False


def _definite(f: Any, values: dict[Any, float]) -> bool:
    """Whether sympy shows ``f`` (the parameters at ``values``) positive or negative for all real values of its
    symbols (declared real): a factor with no real zero, which no motion reaches."""
    fixed = f.subs({k: v for k, v in values.items() if k in f.free_symbols})
    return bool(fixed.is_positive) or bool(fixed.is_negative)


def _rational(expr: Any) -> bool:
    """Whether ``expr`` is a rational function: sums, products and integer powers of symbols and numbers only."""
    import sympy

    for node in _nodes(expr):
        if isinstance(node, sympy.Pow) and not node.exp.is_Integer:
            return False
        if isinstance(node, sympy.Function):
            return False
    return True


def _quotients(expr: Any) -> Any:
    """``expr`` with ``tan``, ``cot``, ``sec``, ``csc`` (and ``tanh``, ``coth``) written as quotients of sines
    and cosines: the same function, whose derivatives show the denominators."""
    import sympy

    return expr.replace(sympy.tan, lambda u: sympy.sin(u) / sympy.cos(u)).replace(
        sympy.cot, lambda u: sympy.cos(u) / sympy.sin(u)).replace(
        sympy.sec, lambda u: 1 / sympy.cos(u)).replace(
        sympy.csc, lambda u: 1 / sympy.sin(u)).replace(
        sympy.tanh, lambda u: sympy.sinh(u) / sympy.cosh(u)).replace(
        sympy.coth, lambda u: sympy.cosh(u) / sympy.sinh(u))


def _build(mechanics: Any) -> PoleGuard | None:
    """The guard of ``mechanics`` (module docstring), or ``None`` when its equations of motion have no denominator
    in the coordinates and the time that can vanish.

    The sources, for ``L = q_dot^T M q_dot / 2 - V`` with constraints ``chi`` and forces ``Q``
    (Goldstein, "Classical Mechanics", Sect. 1.4 and 2.4: ``d/dt (M q_dot) - dL/dq = Q + G^T lambda``,
    ``G = dchi/dq``): ``dV/dq``; ``M`` and ``dM/dq``; ``chi``, ``G``, ``dchi/dt`` and their
    derivatives (the hidden constraint and the multipliers); ``Q``; ``dV/dt``.
    """
    import sympy  # the mechanics were built with it: importing it costs nothing here

    symbolic = mechanics.symbolic
    q = list(symbolic.get("coordinates") or ())
    if not q:
        return None
    time = mechanics.time_symbol
    variables = [*q, *([time] if time is not None else [])]
    velocities = set(symbolic.get("velocities") or ())
    V = sympy.sympify(symbolic.get("potential") or 0)
    mass = symbolic.get("mass")
    # the entries a matrix stores (a zero has no denominator): a lattice of n sites has n of its n^2 entries,
    # and reading all of them took 4 s of a 400-site lattice's run
    M = [sympy.sympify(e) for _, e in sorted(mass.todok().items())] if isinstance(mass, sympy.MatrixBase) else \
        [sympy.sympify(e) for e in (mass or [])]
    chis = [sympy.sympify(e) for e in (symbolic.get("constraints") or [])]
    forces = [sympy.sympify(e) for e in (symbolic.get("forces") or [])]
    if not _may_have_poles([V, *M, *chis, *forces]):
        return None  # polynomials in the coordinates, sines, cosines and exponentials: no denominator anywhere
    # tan(u) = sin(u)/cos(u) and its kin: their derivatives (1 + tan(u)**2) hide the denominator
    V, M, chis, forces = (_quotients(V), [_quotients(e) for e in M], [_quotients(e) for e in chis],
                          [_quotients(e) for e in forces])
    sources: list[tuple[str, list[Any]]] = [
        ("the force -dV/dq", [sympy.diff(V, x) for x in q]),
        ("the mass matrix or its derivatives", [*M, *(sympy.diff(e, x) for e in M for x in q)]),
    ]
    if chis:
        gradients = [sympy.diff(c, x) for c in chis for x in variables]
        sources.append(("the constraints' derivatives (the constraint forces)",
                        [*chis, *gradients, *(sympy.diff(g, x) for g in gradients for x in variables)]))
    if forces:
        sources.append(("the applied forces", forces))
    if time is not None:
        sources.append(("the time derivative of the potential", [sympy.diff(V, time)]))
    params = list(symbolic.get("parameters") or ())
    return _guard_of(sources, variables, params, np.asarray(mechanics.params, dtype=float), [V, *M, *chis, *forces],
                     time is not None, skip=velocities)


def _guard_of(sources: list[tuple[str, list[Any]]], variables: list[Any], params: list[Any], values: np.ndarray,
              domain: list[Any], time: bool, skip: set[Any] | frozenset[Any] = frozenset()) -> PoleGuard | None:
    """The guard of the factors of the denominators of ``sources`` (``(origin, expressions)`` pairs) that can vanish
    and make an expression unbounded, compiled as one function of ``variables`` (the time last when ``time``) and
    ``params`` (at ``values``); ``None`` when there is none. Factors in a symbol of ``skip`` are not read;
    ``domain`` holds the expressions whose logarithms and roots bound the real domain."""
    import sympy

    from dirac.analysis.core.divisors import denominator_factors

    at = dict(zip(params, (float(c) for c in values)))
    found: dict[Any, list[str]] = {}
    for origin, exprs in sources:
        for e in exprs:
            e = sympy.sympify(e)
            for f in denominator_factors(e, variables):
                if f.free_symbols & skip:
                    continue  # a factor in the velocities is not read (module docstring)
                if origin in found.get(f, []) or _definite(f, at) or not _unbounded_at(e, f, variables, at):
                    # already found, a factor of one sign on real values (c**2*m**2 + p**2 of a relativistic
                    # particle: no zero to reach), or e stays bounded where f vanishes (sin(x)/x at x = 0)
                    continue
                found.setdefault(f, []).append(origin)
    if not found:
        return None
    bounds = _domain_bounds(domain, variables)
    from dirac.codegen.scalar_backend import scalar_function

    factors = list(found)
    try:
        compiled = scalar_function([*variables, *params], factors)
    except Exception:  # an unusual function: no guard (the run is as before)  # noqa: BLE001
        return None
    guard = PoleGuard(compiled, [str(f) for f in factors], [" and of ".join(found[f]) for f in factors],
                      time, values, [f in bounds for f in factors])
    guard.expressions = factors
    return guard


def _build_analysed(analysed: Any) -> PoleGuard | None:
    """The guard of an :class:`~dirac.flows.analysed.AnalysedSystem`, over its whole phase space ``z``, or ``None``.

    Its flow ``z_dot = J grad H - J grad Phi^T C^{-1} (grad Phi J grad H + d_t Phi)``
    (:mod:`dirac.flows.analysed`) evaluates ``grad H``, ``grad Phi`` and ``d_t Phi``; the
    factors of their denominators are the poles read (in the coordinates, the multipliers
    and the momenta alike: the state is all of ``z``). Where ``C`` alone becomes singular
    the structure of the constraints changes; that is not a pole of an expression, and the
    midpoint step's own solve reports it.
    """
    import sympy

    analysis = analysed.analysis
    z = list(analysis.phase_space)
    time = getattr(analysis, "time", None)
    variables = [*z, *([time] if time is not None else [])]
    H = sympy.sympify(analysed.hamiltonian)
    constraints = [sympy.sympify(c) for c in analysis.second_class]
    if not _may_have_poles([H, *constraints]):
        return None  # polynomials in z, sines, cosines and exponentials: no denominator anywhere
    H, constraints = _quotients(H), [_quotients(c) for c in constraints]

    def derivatives(e: Any, by: list[Any]) -> list[Any]:
        # a rational function's derivatives have the factors of its own reduced denominator, d(a/b) = (a' b - a b')/b^2:
        # it is read as it is (differentiating the constraints of the rigid body's (228), 24 x 30 derivatives,
        # took 100 s of sympy)
        return [e] if _rational(e) else [sympy.diff(e, x) for x in by]

    sources: list[tuple[str, list[Any]]] = [("the gradient of the Hamiltonian", derivatives(H, z))]
    if constraints:
        sources.append(("the gradients of the second-class constraints",
                        [d for c in constraints for d in derivatives(c, z)]))
        if time is not None:
            sources.append(("the time derivatives of the second-class constraints",
                            [d for c in constraints for d in derivatives(c, [time])]))
    guard = _guard_of(sources, variables, list(analysed.parameter_symbols), np.asarray(analysed.params, dtype=float),
                      [H, *constraints], time is not None)
    if guard is not None:
        guard.state = "z"
    return guard


#: points of ``f = 0`` at which an expression's growth toward the zero set is measured
REMOVABLE_SAMPLES = 3
#: distances from ``f = 0`` (along the gradient of ``f``) at which the expression is evaluated
REMOVABLE_DISTANCES = (1e-2, 1e-5)
#: growth of ``|e|`` between those distances (relative to ``1 + |z|``) above which ``f = 0`` is a pole of ``e``
#: (a simple pole grows 1000 x, ``1/sqrt(x)`` 32 x, a bounded expression about 1 x)
POLE_GROWTH = 10.0


def _unbounded_at(e: Any, f: Any, variables: list[Any], values: dict[Any, float]) -> bool:
    """Whether ``e`` grows without bound toward ``f = 0``, a factor of one of its denominators.

    A denominator need not make a pole: ``sin(x)/x`` and the force ``(x cos x - sin x)/x^2``
    of ``V = -sin(x)/x`` stay bounded at ``x = 0`` (a removable singularity), and so does
    ``(x^2 - x)/(x - 1)`` at ``x = 1`` (the factor cancels); the motion passes there. At up to
    :data:`REMOVABLE_SAMPLES` points ``z`` of ``f = 0`` (found by Newton steps along ``grad f``
    from seeded random points, the parameters at their values) ``e`` is evaluated at
    ``z + d (1 + max |z|) n`` on both sides, ``n = grad f / |grad f|``, for the distances ``d``
    of :data:`REMOVABLE_DISTANCES`: a pole of order ``k`` grows by ``1000^k`` between them, a
    bounded expression by about 1. True when the growth exceeds :data:`POLE_GROWTH` (or ``e``
    is not finite there) at some point, and also when no point of ``f = 0`` is found or the
    evaluation fails: a factor not shown removable stays a pole.
    """
    import sympy

    try:
        at = {k: v for k, v in values.items() if k in e.free_symbols or k in f.free_symbols}
        e_at, f_at = e.subs(at), f.subs(at)
        e_fn = sympy.lambdify(variables, e_at, "math")
        f_fn = sympy.lambdify(variables, f_at, "math")
        grad_fn = sympy.lambdify(variables, [sympy.diff(f_at, x) for x in variables], "math")
    except Exception:  # an expression lambdify cannot print: not shown removable  # noqa: BLE001
        return True
    rng = np.random.default_rng(20241129)
    found_points = 0
    for _ in range(4 * REMOVABLE_SAMPLES):
        z = rng.normal(size=len(variables))
        try:
            for _ in range(60):  # Newton's method along the gradient onto f = 0
                g = np.array(grad_fn(*z), dtype=float)
                value = float(f_fn(*z))
                norm2 = float(g @ g)
                if not (math.isfinite(value) and norm2 > 0.0):
                    break
                if abs(value) <= 1e-13 * (1.0 + float(np.abs(z).max())):
                    break
                z = z - value * g / norm2
            g = np.array(grad_fn(*z), dtype=float)
            if not abs(float(f_fn(*z))) <= 1e-12 * (1.0 + float(np.abs(z).max())) or not float(g @ g) > 0.0:
                continue
            n = g / math.sqrt(float(g @ g))
            scale = 1.0 + float(np.abs(z).max())
            near, far = (max(abs(float(e_fn(*(z + side * d * scale * n)))) for side in (1.0, -1.0))
                         for d in (REMOVABLE_DISTANCES[1], REMOVABLE_DISTANCES[0]))
        except (ArithmeticError, ValueError, TypeError):
            continue
        if not (math.isfinite(near) and math.isfinite(far)):
            return True
        found_points += 1
        if near > POLE_GROWTH * max(far, 1e-300):
            return True
        if found_points >= REMOVABLE_SAMPLES:
            return False
    return found_points == 0


def _domain_bounds(exprs: list[Any], variables: list[Any]) -> set[Any]:
    """The factors of the arguments of ``log`` and of the bases of fractional powers in ``exprs``: where
    the real domain of the expressions ends (``x`` of ``log(x)`` or ``sqrt(x)``)."""
    import sympy

    from dirac.analysis.core.divisors import denominator_factors

    bounds: set[Any] = set()
    for expr in exprs:
        for node in _nodes(expr):
            if isinstance(node, sympy.log):
                inner = node.args[0]
            elif isinstance(node, sympy.Pow) and node.exp.is_Rational and not node.exp.is_Integer:
                inner = node.base
            else:
                continue
            bounds.update(denominator_factors(1 / inner, variables))
    return bounds


def barrier_before(guard: PoleGuard, mechanics: Any, after: np.ndarray, t: float,
                   energies: np.ndarray) -> tuple[float, float] | None:
    """``(V, E)`` where the potential exceeds the start energy ``E`` of its member on the chord from the guard's
    last reading (:attr:`PoleGuard.last_state`) to the first zero of a pole factor that changed sign towards
    ``after`` (batches ``(B, n)``); None if nowhere, or if the guard has no reading of that shape.

    The exact motion of a conservative system keeps ``V(q) <= E`` (Arnold, "Mathematical Methods of
    Classical Mechanics", Sect. 4): where ``V`` exceeds ``E`` between the last reading and the pole, that
    motion cannot have come there along the step. The chord is cut at the zero by bisection of that factor
    (60 halvings) and ``V`` read at ``10^-k`` of the cut chord before it, ``k = 1 .. 6`` (a pole of ``V``
    grows by orders there).
    """
    before = guard.last_state
    if before is None or before.shape != np.shape(after):
        return None
    potential = mechanics.module.function("potential")
    start, end = guard.read(before, t), guard.read(after, t)
    before, after = np.atleast_2d(before), np.atleast_2d(after)
    for b, k in zip(*np.nonzero(np.sign(start) * np.sign(end) < 0.0)):
        lo, hi = 0.0, 1.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            value = guard.read(before[b] + mid * (after[b] - before[b]), t)[0, k]
            if np.sign(value) == np.sign(start[b, k]):
                lo = mid
            else:
                hi = mid
        for power in range(1, 7):
            s = lo * (1.0 - 10.0 ** -power)
            with np.errstate(all="ignore"):
                v = float(potential(np.ascontiguousarray(before[b] + s * (after[b] - before[b])), t, mechanics.params))
            if v > energies[b]:
                return v, float(energies[b])
    return None


def pole_guard(mechanics: Any) -> PoleGuard | None:
    """A fresh :class:`PoleGuard` of a :class:`~dirac.flows.mechanics.MechanicalSystem` for one run, or ``None``.

    The factors are found and compiled once per system (kept on it); each call gives a guard
    with no reading yet.
    """
    return _fresh(built_once(mechanics, "_pole_guard", _build))


def _fresh(cached: Any) -> PoleGuard | None:
    """A guard with no reading yet of the factors of ``cached`` (a guard built once), or ``None``."""
    if not isinstance(cached, PoleGuard):
        return None
    guard = PoleGuard(cached._values, cached.factors, cached.origins, cached._time, np.array(cached._params),
                      cached.bounds)
    guard.expressions, guard.state = cached.expressions, cached.state
    return guard


def analysed_pole_guard(analysed: Any) -> PoleGuard | None:
    """A fresh :class:`PoleGuard` of an :class:`~dirac.flows.analysed.AnalysedSystem` for one run (read at its
    state ``z``), or ``None``; built once per system, as :func:`pole_guard`."""
    return _fresh(built_once(analysed, "_pole_guard", _build_analysed))


def message(system: str, crossing: PoleCrossing, method: str) -> str:
    """The error text of a :class:`PoleCrossing` of the run of ``system`` with ``method``: what, where and the remedy."""
    text = f"the run of {system!r} with method {method} stopped: {crossing}; "
    if crossing.turn:
        text += ("if the exact motion turns before the pole (a repelling pole, or a close pass such as a periapsis), "
                 "a smaller dt resolves the turn; if it reaches the pole, ")
    return text + REMEDY

