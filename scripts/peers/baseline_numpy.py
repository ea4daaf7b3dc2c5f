# The built-in `baseline` datapath of specfx as a vectorised int64 numpy model, written from
# docs/arithmetic.md (sections 2, 3 and 5) alone, for scripts/bench-peers.
#
# Every value is a raw integer code. RND drops s bits as floor((x + 2^(s-1)) / 2^s) (an
# arithmetic right shift); SAT clamps to the format's code range. Per n (baseline: plain
# variant, k = 4, clamp cutoff):
#
#   c   = min(c_raw, 32768)                      u1.15, clamped to 1.0
#   d   = c - 32768                              s1.15, exact
#   t   = SAT_s2.16(RND_3(d * n))                d (F 15) times slope n (F 4): F 19 -> 16
#   b   = SAT_u1.16(max(t + 65536, 0))           offset 1 (F 0) aligned to F 16; clamp cutoff
#   sq  = SAT_u1.16(RND_16(sq * sq))   x4        F 32 -> 16
#   out = SAT_u8.16(RND_16(sq4 * coef_raw))      F 32 -> 16
#
# coef_raw(n) = RND of the f64 1 / (2 pi ((1 / (m + 1)) / (n / m))) (m = 16; phong, exact
# source, n >= m: the table of section 3.1.2), converted exactly to a rational and rounded
# once to 16 fraction bits.
import math

import numpy as np

ONE = 1 << 15          # code of 1.0 in u1.15
M = 16                 # m = 2^k, k = 4
CODES = np.arange(ONE + 1, dtype=np.int64)   # c_raw = 0..=32768


def coef_f64(n):
    """The f64 coefficient of section 3.1.2 (phong, exact, n >= m), in the table's order."""
    return 1.0 / (2.0 * math.pi * ((1.0 / (M + 1)) / (n / M)))


def rnd_exact(value, frac):
    """An f64 rounded once with RND (ties toward +inf) to `frac` fraction bits, exactly."""
    num, den = float(value).as_integer_ratio()
    # floor(num / den * 2^frac + 1/2)
    return (num * (1 << (frac + 1)) + den) // (2 * den)


def coef_raw(n):
    return rnd_exact(coef_f64(n), 16)


def coef_raw_17n(n):
    """The brief's alternative: RND of the f64 17 n / (32 pi) (the doc says: same codes)."""
    return rnd_exact(17 * n / (32 * math.pi), 16)


def _sat(x, lo, hi):
    return np.clip(x, lo, hi, out=x)


def outputs(ns, coefs):
    """out_raw for every (n in ns) x (c_raw in 0..=32768): an int64 array (len(ns), 32769)."""
    n = np.asarray(ns, dtype=np.int64)[:, None]
    coef = np.asarray(coefs, dtype=np.int64)[:, None]
    c = np.minimum(CODES, ONE)[None, :]
    d = c - ONE                                           # s1.15, exact
    t = _sat((d * n + 4) >> 3, -(1 << 17), (1 << 17) - 1)  # s2.16, RND, SAT
    b = t + (1 << 16)                                     # + offset, F 16, exact
    np.maximum(b, 0, out=b)                               # clamp cutoff
    _sat(b, 0, (1 << 17) - 1)                             # u1.16 (never overflows)
    s = b
    for _ in range(4):
        s = _sat((s * s + (1 << 15)) >> 16, 0, (1 << 17) - 1)   # u1.16, RND, SAT
    return _sat((s * coef + (1 << 15)) >> 16, 0, (1 << 24) - 1)  # u8.16, RND, SAT


def per_n_sums(ns, coefs, block=32):
    """The checksum terms: for each n, the wrapping sum of out_raw * (c_raw + 1) * n."""
    weight = (CODES + 1).astype(np.uint64)[None, :]
    sums = []
    for i in range(0, len(ns), block):
        nb = ns[i:i + block]
        out = outputs(nb, coefs[i:i + block]).astype(np.uint64)
        out *= weight
        out *= np.asarray(nb, dtype=np.uint64)[:, None]
        sums.extend(int(v) for v in out.sum(axis=1, dtype=np.uint64))  # wraps mod 2^64
    return sums
