"""Rows of numbers as C's ``%.{p}g`` writes them, compiled (text recorders write millions).

``format_g_rows(values, p)`` (``format_g_bytes``: the same as bytes; ``times``: a first column)
gives the same text as ``"".join(" ".join("%.{p}g" % v for v in row) + "\\n" for row in values)``
— Python's (and C's) correctly rounded ``%g`` — for every
double, 9-22 times faster than that expression (blocks of 20 and of 2 columns at p = 16).

How it stays exact: a value v ≠ 0 with decimal exponent X (10^X ≤ |v| < 10^(X+1)) is scaled
(from frexp's binary exponent and one comparison with 10^(X+1))
to y = |v| · 10^(p−1−X), a number below 10^p, in double-double arithmetic (``10^k`` from a table
of double-double powers correctly rounded from exact fractions, the product by Dekker's exact
splitting): y is known to a relative 2⁻¹⁰³, about 10⁻¹⁴ absolute at p = 17. Its integer part
rounded half to even gives the p significant digits, unless the fraction lies within 10⁻⁹ of
½ (a tie or too near one to decide: e.g. 2⁻²⁴ = 5.9604644775390625e-08 at p = 16) or the value
is outside the table's range (|X| > 280) or not finite: those few values are formatted by Python
instead, as is everything when p > 17. Then C's ``%g`` rules: fixed notation when −4 ≤ X < p (X after rounding),
exponential otherwise (``e±XX``, at least two exponent digits), trailing zeros and a trailing
point removed, ``-0`` for negative zero. The per-value helpers are inlined into the row loop (numba's ``inline='always'``),
and the digits are written right to left straight into place (no scratch copy: 1400 rows of a
time and a value at p = 16 went from 150 to 125 µs).
"""
import functools
import math
from fractions import Fraction

import numpy as np
from numba import njit

POWER_RANGE = 300           # the table holds 10^k for |k| <= POWER_RANGE
EXPONENT_LIMIT = 280        # values with |X| above this go to Python (then |p − 1 − X| <= 297)
MAX_PRECISION = 17          # digits the int64 path carries (10^17 < 2^63)
PYTHON_NUMBERS = 8          # numbers of a chunk up to which Python formats them (a per-step loop's: a time and
                            # a value took 1.9 µs so, 3.8 in a call of the compiled code; alike at 8 numbers)
SLOT = 32                   # characters per value at most: '-' + 17 digits + '.' + 'e-308' fits


def _power_table():
    """10^k, k = −POWER_RANGE … POWER_RANGE, as double-doubles (hi, lo): hi the correctly
    rounded double, lo the correctly rounded rest."""
    hi = np.empty(2 * POWER_RANGE + 1)
    lo = np.empty(2 * POWER_RANGE + 1)
    for i, k in enumerate(range(-POWER_RANGE, POWER_RANGE + 1)):
        exact = Fraction(10) ** k
        h = float(exact)
        hi[i], lo[i] = h, float(exact - Fraction(h))
    return hi, lo


POW_HI, POW_LO = _power_table()


@njit(cache=True, inline="always")
def _two_product(a, b):
    """(p, e) with p + e = a · b exactly (Dekker's splitting, no FMA needed)."""
    p = a * b
    split = 134217729.0                     # 2^27 + 1
    t = split * a
    a_hi = t - (t - a)
    a_lo = a - a_hi
    t = split * b
    b_hi = t - (t - b)
    b_lo = b - b_hi
    e = ((a_hi * b_hi - p) + a_hi * b_lo + a_lo * b_hi) + a_lo * b_lo
    return p, e


@njit(cache=True, inline="always")
def _below_power(v, k, pow_hi, pow_lo):
    """|v| < 10^k, decided on the double-double power."""
    h = pow_hi[k + POWER_RANGE]
    if v != h:
        return v < h
    return pow_lo[k + POWER_RANGE] > 0.0


@njit(cache=True, inline="always")
def _scaled_digits(v, k, pow_hi, pow_lo):
    """round-half-even(|v| · 10^k) as int64, and whether the rounding is too close to call."""
    p, e = _two_product(v, pow_hi[k + POWER_RANGE])
    e += v * pow_lo[k + POWER_RANGE]
    whole = np.floor(p)
    frac = (p - whole) + e                  # p − whole is exact: both are near the same integer
    shift = np.floor(frac)
    frac -= shift
    n = np.int64(whole) + np.int64(shift)   # in integers: above 2^53 a double holds even numbers only
    doubtful = abs(frac - 0.5) < 1e-9
    if frac > 0.5 or (frac == 0.5 and n % 2 == 1):
        n += 1
    return n, doubtful


@njit(cache=True, inline="always")
def _put_digits(u, used, point, out, pos):
    """The ``used`` decimal digits of ``u`` (uint64, no more digits than that) into ``out`` from
    ``pos``, a '.' after the first ``point`` (<= ``used``) of them if any follow; returns the
    position after the last. Written right to left, straight into place (no scratch copy)."""
    end = pos + used + (1 if point < used else 0)
    k = end - 1
    for _ in range(used - point):
        q = u // np.uint64(10)
        out[k] = np.uint8(48 + (u - q * np.uint64(10)))
        u = q
        k -= 1
    if point < used:
        out[k] = 46                         # '.'
        k -= 1
    for _ in range(point):
        q = u // np.uint64(10)
        out[k] = np.uint8(48 + (u - q * np.uint64(10)))
        u = q
        k -= 1
    return end


@njit(cache=True, inline="always")
def _format_value(v, precision, top, pow_hi, pow_lo, out, pos):
    """``%.{precision}g`` of ``v`` written into ``out`` from ``pos``; returns the position after
    it, or −1 where Python must format it (``top`` = 10^precision)."""
    if v != v or v == np.inf or v == -np.inf:
        return -1
    if math.copysign(1.0, v) < 0.0:
        out[pos] = 45                       # '-'
        pos += 1
        v = -v
    if v == 0.0:
        out[pos] = 48
        return pos + 1
    x = int(np.floor((math.frexp(v)[1] - 1) * 0.30102999566398120))   # floor(log10 2^(e-1)): 10^x <= v < 10^(x+2)
    if x < -EXPONENT_LIMIT or x > EXPONENT_LIMIT:
        return -1
    if not _below_power(v, x + 1, pow_hi, pow_lo):
        x += 1
    n, doubtful = _scaled_digits(v, precision - 1 - x, pow_hi, pow_lo)
    if doubtful:
        return -1
    if n >= top:                            # rounded up to the next power of ten
        n //= 10
        x += 1
    u = np.uint64(n)                        # unsigned: a division by 10 without Python's sign rules
    used = precision                        # the significant digits once trailing zeros are dropped
    while used > 1:
        q = u // np.uint64(10)
        if u != q * np.uint64(10):
            break
        u = q
        used -= 1
    if -4 <= x < precision:                 # fixed notation
        if x < 0:                           # 0.000ddd
            out[pos] = 48
            out[pos + 1] = 46
            pos += 2
            for _ in range(-x - 1):
                out[pos] = 48
                pos += 1
            return _put_digits(u, used, used, out, pos)
        if used > x + 1:                    # ddd.ddd
            return _put_digits(u, used, x + 1, out, pos)
        pos = _put_digits(u, used, used, out, pos)      # an integer: its digits, then zeros
        for _ in range(x + 1 - used):
            out[pos] = 48
            pos += 1
        return pos
    pos = _put_digits(u, used, 1, out, pos)             # exponential notation: d.ddde±XX
    out[pos] = 101                          # 'e'
    out[pos + 1] = 45 if x < 0 else 43
    pos += 2
    ax = -x if x < 0 else x
    if ax >= 100:
        out[pos] = 48 + ax // 100
        pos += 1
    out[pos] = 48 + (ax // 10) % 10
    out[pos + 1] = 48 + ax % 10
    return pos + 2


@njit(cache=True)
def _format_rows(times, values, precision, pow_hi, pow_lo, out, gaps):
    """The rows of ``values (n, m)`` into ``out``, each preceded by ``times[r]`` unless ``times``
    is empty: numbers separated by a space, a newline after each row. A value Python must format
    leaves a gap: ``gaps[g] = (position in out, row, column)``, column -1 for the time. Returns
    (length used, number of gaps)."""
    top = np.int64(1)                       # 10^precision
    for _ in range(precision):
        top *= 10
    first = -1 if times.shape[0] else 0
    last = values.shape[1] - 1
    pos, n_gaps = 0, 0
    for r in range(values.shape[0]):
        for c in range(first, last + 1):
            v = times[r] if c < 0 else values[r, c]
            end = _format_value(v, precision, top, pow_hi, pow_lo, out, pos)
            if end < 0:
                gaps[n_gaps, 0], gaps[n_gaps, 1], gaps[n_gaps, 2] = pos, r, c
                n_gaps += 1
            else:
                pos = end
            out[pos] = 10 if c == last else 32
            pos += 1
    return pos, n_gaps


@functools.lru_cache(maxsize=64)
def _line(precision, count):
    """The %-format of a row of ``count`` numbers ``%.{precision}g`` (Python's formatting)."""
    return " ".join([f"%.{precision}g"] * count) + "\n"


def format_g_bytes(values, precision=6, times=None):
    """``values (n, m)`` as n lines of m numbers ``%.{precision}g`` separated by spaces, each
    line ending in a newline and, with ``times (n,)``, starting with its time (OpenSees's text
    recorder rows), as ASCII bytes; the text of C's / Python's ``%g`` for every double (module
    docstring). A chunk of up to PYTHON_NUMBERS numbers (a per-step loop's) is formatted by
    Python's ``%``, sooner than a call of the compiled code there."""
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 2:
        raise ValueError(f"format_g_rows: values must be (n, m), got shape {values.shape}")
    n, m = values.shape
    times = np.zeros(0) if times is None else np.ascontiguousarray(times, dtype=np.float64)
    if times.shape[0] and times.shape != (n,):
        raise ValueError(f"format_g_rows: {n} rows but times of shape {times.shape}")
    if m == 0 and not times.shape[0]:
        return b"\n" * n
    precision = max(int(precision), 1)      # C: a precision of 0 is taken as 1 for %g
    if precision > MAX_PRECISION or values.size + times.shape[0] <= PYTHON_NUMBERS:
        # more digits than an int64 carries, or a few numbers: Python's text (the same text)
        if times.shape[0]:
            flat = []
            for t, row in zip(times.tolist(), values.tolist()):
                flat.append(t)
                flat += row
        else:
            flat = values.ravel().tolist()
        return ((_line(precision, m + (times.shape[0] > 0)) * n) % tuple(flat)).encode("ascii")
    values = np.ascontiguousarray(values)
    size = values.size + times.shape[0]
    out = np.empty(size * (SLOT + 1), dtype=np.uint8)
    gaps = np.empty((size, 3), dtype=np.int64)
    used, n_gaps = _format_rows(times, values, precision, POW_HI, POW_LO, out, gaps)
    if n_gaps == 0:
        return out[:used].tobytes()
    pieces, done = [], 0
    for position, r, c in gaps[:n_gaps].tolist():
        value = times[r] if c < 0 else values[r, c]
        pieces += [out[done:position].tobytes(), (f"%.{precision}g" % value).encode("ascii")]
        done = position
    pieces.append(out[done:used].tobytes())
    return b"".join(pieces)


def format_g_rows(values, precision=6, times=None):
    """:func:`format_g_bytes` as a str."""
    return format_g_bytes(values, precision, times).decode("ascii")
