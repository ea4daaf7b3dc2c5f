# The built-in `baseline` datapath of specfx as a vectorised int64 numpy model, written from
# docs/arithmetic.md (sections 2, 3 and 5) alone, for scripts/bench-peers; also the baseline
# with its input widened (bench-peers --frac F), whose formats are parameters here.
#
# Every value is a raw integer code. RND drops s bits as floor((x + 2^(s-1)) / 2^s) (an
# arithmetic right shift); SAT clamps to the format's code range. Per n (baseline: plain
# variant, k = 4, clamp cutoff), with fc the fraction bits of c and d (baseline 15) and ft
# those of t, b and the squarings (baseline 16); coef and out stay u8.16:
#
#   c   = min(c_raw, 2^fc)                       u1.fc, clamped to 1.0
#   d   = c - 2^fc                               s1.fc, exact (section 3.2 step 2, Fd = Fc)
#   t   = SAT_s2.ft(RND_st(d * n))               d (F fc) times slope n (F 4): st = fc + 4 - ft
#   b   = SAT_u1.ft(max(t + 2^ft, 0))            offset 1 (F 0) aligned to F ft; clamp cutoff
#   sq  = SAT_u1.ft(RND_ft(sq * sq))   x4        F 2 ft -> ft
#   out = SAT_u8.16(RND_ft(sq4 * coef_raw))      F ft + 16 -> 16
#
# The baseline is fc = 15, ft = 16 (st = 3); the widened datapath of --frac F is fc = ft = F
# (st = 4). int64 holds every intermediate for fc, ft <= 24 (|d * n| < 2^35, sq * sq < 2^50,
# sq4 * coef_raw < 2^49), and the checksums wrap in uint64.
#
# coef_raw(n) = RND of the f64 1 / (2 pi ((1 / (m + 1)) / (n / m))) (m = 16; phong, exact
# source, n >= m: the table of section 3.1.2), converted exactly to a rational and rounded
# once to 16 fraction bits; it does not depend on fc or ft.
import math

import numpy as np

ONE = 1 << 15          # code of 1.0 in u1.15 (the baseline's input)
M = 16                 # m = 2^k, k = 4
CODES = np.arange(ONE + 1, dtype=np.int64)   # c_raw = 0..=32768 (the baseline's codes)


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


def codes(fc=15):
    """c_raw = 0..=2^fc, the input codes up to 1.0, as int64."""
    return CODES if fc == 15 else np.arange((1 << fc) + 1, dtype=np.int64)


def outputs(ns, coefs, fc=15, ft=16):
    """out_raw for every (n in ns) x (c_raw in 0..=2^fc): an int64 array (len(ns), 2^fc + 1)."""
    st = fc + 4 - ft                                      # bits t's rounding drops
    if not (1 <= st and 1 <= ft <= 24 and fc <= 24):
        raise ValueError(f"outputs: formats fc = {fc}, ft = {ft} are outside this model")
    one = 1 << fc
    n = np.asarray(ns, dtype=np.int64)[:, None]
    coef = np.asarray(coefs, dtype=np.int64)[:, None]
    c = np.minimum(codes(fc), one)[None, :]
    d = c - one                                           # s1.fc, exact
    t = _sat((d * n + (1 << (st - 1))) >> st,             # s2.ft, RND, SAT
             -(1 << (ft + 1)), (1 << (ft + 1)) - 1)
    b = t + (1 << ft)                                     # + offset, F ft, exact
    np.maximum(b, 0, out=b)                               # clamp cutoff
    _sat(b, 0, (1 << (ft + 1)) - 1)                       # u1.ft (never overflows)
    s = b
    for _ in range(4):
        s = _sat((s * s + (1 << (ft - 1))) >> ft, 0, (1 << (ft + 1)) - 1)   # u1.ft, RND, SAT
    return _sat((s * coef + (1 << (ft - 1))) >> ft, 0, (1 << 24) - 1)       # u8.16, RND, SAT


def per_n_sums(ns, coefs, fc=15, ft=16, block=None):
    """The checksum terms: for each n, the wrapping sum of out_raw * (c_raw + 1) * n.
    `block` n values at a time (default: about 32 x 32769 evaluations a block, 32 n for the
    baseline)."""
    cs = codes(fc)
    if block is None:
        block = max(1, (32 * CODES.size) // cs.size)
    weight = (cs + 1).astype(np.uint64)[None, :]
    sums = []
    for i in range(0, len(ns), block):
        nb = ns[i:i + block]
        out = outputs(nb, coefs[i:i + block], fc, ft).astype(np.uint64)
        out *= weight
        out *= np.asarray(nb, dtype=np.uint64)[:, None]
        sums.extend(int(v) for v in out.sum(axis=1, dtype=np.uint64))  # wraps mod 2^64
    return sums
