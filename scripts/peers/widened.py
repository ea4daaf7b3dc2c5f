# The baseline datapath widened to F fraction bits, shared by scripts/bench-scaling and
# scripts/bench-peers (--frac F): every stage from c to the squarings at F fraction bits
# (c u1.F, d s1.F, t s2.F, b and the squarings u1.F); everything else (variant, k = 4, the
# clamp cutoff, n = 16..=1024, the coefficient and the output, both u8.16) is the baseline's,
# since a configuration file states only what differs from it (docs/arithmetic.md 4.1).
#
# At F = 15 this is NOT the baseline: the baseline's t is s2.16 and b and the squarings u1.16.
# `fractions(F)` gives the fraction bits of the stages (c and d, then t, b and the squarings).

CONFIG = """name = "w{f}"
[c]
format = "u1.{f}"
[d]
format = "s1.{f}"
[t]
format = "s2.{f}"
[b]
format = "u1.{f}"
[square]
format = "u1.{f}"
"""


def config_text(f):
    """The TOML text of the baseline widened to f fraction bits."""
    return CONFIG.format(f=f)


def fractions(f):
    """(Fc = Fd, Ft = Fb = Fsq) of the widened datapath."""
    return f, f


def describe(f):
    """The widened formats, for a table's header line."""
    return (f"c u1.{f}, d s1.{f}, t s2.{f}, b and the squarings u1.{f}; "
            "coef and out u8.16 as the baseline's")
