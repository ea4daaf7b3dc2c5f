# The built-in `baseline` datapath of specfx in APyTypes (APyFixedArray), written from
# docs/arithmetic.md (sections 2, 3 and 5), vectorised over arrays, for scripts/bench-peers;
# also the baseline with its input widened (bench-peers --frac F): fc, the fraction bits of c
# and d (baseline 15), and ft, those of t, b and the squarings (baseline 16), are parameters.
#
# APyTypes formats are two's complement only. An unsigned specfx format uI.F becomes the
# signed s(I+1).F (int_bits = I + 1), which has the same LSB and the same largest value; its
# extra negative codes are never produced here (every unsigned stage is non-negative), so SAT
# saturates exactly as it does on uI.F. Arithmetic between APyFixed values is exact (full
# precision); every stage ends with one cast(int_bits, frac_bits, QuantizationMode.RND,
# OverflowMode.SAT): RND is round to nearest with ties toward +infinity, as in specfx.
#
#   c   = min(c, 1.0)                       s2.fc (u1.fc)
#   d   = c - 1.0                           cast to s1.fc (exact)
#   t   = Q(d * slope)                      slope = n with 4 fraction bits; s2.ft, RND, SAT
#   b   = Q(max(t + 1.0, 0))                s2.ft (u1.ft); max(x, 0) = (x + |x|) >> 1, exact
#   sq  = Q(sq * sq)   four times           s2.ft (u1.ft), RND, SAT
#   out = Q(sq4 * coef)                     s9.16 (u8.16), RND, SAT
#
# coef: the f64 of docs/arithmetic.md 3.1.2 held exactly (APyFixed.from_float with 64
# fraction bits), then cast once to s9.16 with RND; it does not depend on fc or ft.
import numpy as np
import apytypes as apy
from apytypes import APyFixed, APyFixedArray, OverflowMode, QuantizationMode

from baseline_numpy import coef_f64

RND = QuantizationMode.RND
SAT = OverflowMode.SAT
ONE_CODE = 1 << 15
CODES = np.arange(ONE_CODE + 1, dtype=np.uint64)  # c_raw = 0..=32768 (the baseline's codes)

ONE_C = APyFixed(ONE_CODE, int_bits=2, frac_bits=15)  # 1.0 in s2.15
ONE_OFFSET = APyFixed(1, int_bits=2, frac_bits=0)      # offset 1, u1.0 -> s2.0


def coef_raw(n):
    exact = APyFixed.from_float(coef_f64(n), int_bits=10, frac_bits=64)
    return int(exact.cast(int_bits=9, frac_bits=16, quantization=RND, overflow=SAT).to_bits())


def codes(fc=15):
    """c_raw = 0..=2^fc, the input codes up to 1.0, as uint64."""
    return CODES if fc == 15 else np.arange((1 << fc) + 1, dtype=np.uint64)


def _relu(x):
    return (x + abs(x)) >> 1


def outputs(ns, coefs, fc=15, ft=16):
    """out_raw for every (n in ns) x (c_raw in 0..=2^fc), as a uint64 numpy array, flat."""
    k = len(ns)
    cs = codes(fc)
    one_c = ONE_C if fc == 15 else APyFixed(1 << fc, int_bits=2, frac_bits=fc)  # 1.0, s2.fc
    c = APyFixedArray(np.tile(cs, k), int_bits=2, frac_bits=fc)
    slope = APyFixedArray(np.repeat(np.asarray(ns, dtype=np.uint64), cs.size),
                          int_bits=8, frac_bits=4)
    coef = APyFixedArray(np.repeat(np.asarray(coefs, dtype=np.uint64), cs.size),
                         int_bits=9, frac_bits=16)
    c = one_c - _relu(one_c - c)                          # min(c, 1.0)
    d = (c - one_c).cast(int_bits=1, frac_bits=fc)        # exact: d in [-1, 0]
    t = (d * slope).cast(int_bits=2, frac_bits=ft, quantization=RND, overflow=SAT)
    b = _relu(t + ONE_OFFSET).cast(int_bits=2, frac_bits=ft, quantization=RND, overflow=SAT)
    s = b
    for _ in range(4):
        s = (s * s).cast(int_bits=2, frac_bits=ft, quantization=RND, overflow=SAT)
    out = (s * coef).cast(int_bits=9, frac_bits=16, quantization=RND, overflow=SAT)
    return out.to_bits(numpy=True).astype(np.uint64)


def per_n_sums(ns, coefs, fc=15, ft=16, block=None):
    """For each n, the wrapping sum of out_raw * (c_raw + 1) * n; `block` n values at a time
    (default: about 16 x 32769 evaluations a block, 16 n for the baseline)."""
    cs = codes(fc)
    if block is None:
        block = max(1, (16 * CODES.size) // cs.size)
    weight = cs + np.uint64(1)
    sums = []
    for i in range(0, len(ns), block):
        nb = ns[i:i + block]
        out = outputs(nb, coefs[i:i + block], fc, ft).reshape(len(nb), cs.size)
        out *= weight[None, :]
        out *= np.asarray(nb, dtype=np.uint64)[:, None]
        sums.extend(int(v) for v in out.sum(axis=1, dtype=np.uint64))
    return sums


def version():
    return apy.__version__
