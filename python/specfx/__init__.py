"""specfx: the bit-accurate model of a division-free fixed-point specular (cos^n) datapath.

The same engine as the ``specfx`` command line, for cocotb scoreboards and notebooks::

    import numpy as np, specfx
    dp = specfx.Datapath("baseline")            # a built-in name, a TOML file or a vector dir
    dp.eval(32768, 64)                          # one output code (c = 1.0, n = 64)
    c = np.arange(dp.input_codes.start, dp.one_code + 1)
    out = dp.eval(c, 64)                        # numpy in, numpy out (the GIL is released)
    p = dp.probes(c, 64)                        # every stage's value and overflow event

Raw codes are integers (two's complement for signed formats, every format up to 64 bits).
An input outside the model's domain (an n not in the configuration's set, a code outside the
input format) raises ``ValueError`` with the command line's message, as does a configuration
the command line refuses; so do a negative or too large integer, a float or a bool where an
integer code, exponent or seed is expected (never truncated), and a read-only ``out=``. A
result too large for the memory raises ``MemoryError``. Nothing raises Rust's
``PanicException``.
"""

import json
import operator
from typing import Any, Dict, List, Optional, Union

import numpy as np

from ._specfx import Machine as _Machine
from ._specfx import Model as _Model
from ._specfx import __version__

__all__ = ["Datapath", "Machine", "EVENTS", "__version__"]

#: The overflow events of ``probes()``, by code.
EVENTS = ("none", "wrapped", "saturated", "zeroed")

IntOrArray = Union[int, np.integer, np.ndarray]


def _codes(x: Any, what: str, dtype: Any) -> np.ndarray:
    """``x`` as an integer array of ``dtype``, refusing floats and values that do not fit."""
    a = np.asarray(x)
    if a.dtype == np.bool_ or not np.issubdtype(a.dtype, np.integer):
        raise ValueError(f"{what}: expected integer codes, got an array of {a.dtype}")
    info, have = np.iinfo(dtype), np.iinfo(a.dtype)
    # Only a type wider than dtype, or signed into unsigned, can hold a value that does not fit.
    if a.size and (have.min < info.min or have.max > info.max):
        lo, hi = a.min(), a.max()
        if lo < info.min or hi > info.max:
            bad = lo if lo < info.min else hi
            raise ValueError(f"{what} = {bad} does not fit in {np.dtype(dtype).name}")
    return a.astype(dtype, copy=False)


def _int(x: Any, what: str, dtype: Any) -> int:
    """``x``, one integer (a Python or numpy integer, or a 0-d integer array), as an ``int``
    that fits in ``dtype``: a float (``16.5``), a bool or a value that does not fit raises
    ``ValueError`` naming ``what`` (never truncated, never ``OverflowError``)."""
    if isinstance(x, np.ndarray) and x.ndim == 0:
        x = x[()]
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, np.integer)):
        raise ValueError(f"{what}: expected an integer, got {type(x).__name__}")
    v = operator.index(x)
    info = np.iinfo(dtype)
    if not info.min <= v <= info.max:
        raise ValueError(f"{what} = {v} does not fit in {np.dtype(dtype).name}")
    return v


class Datapath:
    """A validated datapath: its configuration, per-n constants and bit-accurate evaluation.

    ``Datapath(config="baseline", n=None)`` reads ``config`` as ``specfx --config`` does: a
    built-in name (``baseline``), a TOML file, or a vector directory written by
    ``specfx vectors`` (or its ``manifest.json``; the whole directory is verified). ``n``
    (e.g. ``"16..=64"``) replaces the exponent set. ``Datapath.from_toml(text)`` takes the TOML
    text itself.
    """

    def __init__(self, config: str = "baseline", n: Optional[str] = None) -> None:
        self._m = _Model.open(str(config), n)

    @classmethod
    def from_toml(cls, text: str) -> "Datapath":
        """The datapath of a configuration's TOML text (merged onto ``baseline``)."""
        dp = cls.__new__(cls)
        dp._m = _Model.from_toml(text)
        return dp

    def __repr__(self) -> str:
        return f"Datapath({self.name!r}, k={self.k}, n={len(self.n)} exponents)"

    @property
    def name(self) -> str:
        """The configuration's name."""
        return self._m.name()

    @property
    def toml(self) -> str:
        """The whole configuration as TOML."""
        return self._m.toml()

    @property
    def k(self) -> int:
        """The number of squarings (m = 2^k)."""
        return self._m.k()

    @property
    def n(self) -> List[int]:
        """The exponents of the configuration, ascending."""
        return self._m.n()

    @property
    def formats(self) -> Dict[str, str]:
        """Every stage's format (``"u1.15"``), in evaluation order: c, d, t, b, sq1.., coef, out."""
        return dict(self._m.formats())

    @property
    def stages(self) -> List[str]:
        """The stages' names: d, t, b, sq1..sqk, coef, out."""
        return [name for name, _ in self._m.formats()][1:]

    @property
    def input_codes(self) -> range:
        """Every raw code of the input format c."""
        lo, hi, _ = self._m.input_codes()
        return range(lo, hi + 1)

    @property
    def one_code(self) -> int:
        """The raw code of c = 1.0."""
        return self._m.input_codes()[2]

    def constants(self, n: int) -> Dict[str, Any]:
        """The constants of exponent ``n`` as the datapath stores them (raw codes and their
        fraction bits; ``threshold`` is None unless the paper cutoff applies) and their values
        before quantization (``*_value``); ``depth`` is j(n), the squarings n uses (k for a
        fixed depth; the RTL's ``in_depth``)."""
        n = _int(n, "n", np.uint32)
        s, sf, o, of, th, coef, sv, ov, cv, depth = self._m.constants(n)
        return {
            "n": n,
            "slope": s,
            "slope_frac": sf,
            "offset": o,
            "offset_frac": of,
            "threshold": th,
            "coef": coef,
            "slope_value": sv,
            "offset_value": ov,
            "coef_value": cv,
            "depth": depth,
        }

    def _pairs(self, c: IntOrArray, n: IntOrArray):
        """Flat int64 codes and uint32 exponents (or one n), and the shape of the result."""
        cs = _codes(c, "c", np.int64)
        ns = _codes(n, "n", np.uint32)
        if ns.ndim == 0:
            return np.ascontiguousarray(cs.ravel()), None, int(ns), cs.shape
        cs, ns = np.broadcast_arrays(cs, ns)
        shape = cs.shape
        return (
            np.ascontiguousarray(cs.ravel()),
            np.ascontiguousarray(ns.ravel()),
            0,
            shape,
        )

    def eval(
        self, c: IntOrArray, n: IntOrArray, out: Optional[np.ndarray] = None
    ) -> Union[int, np.ndarray]:
        """The output code of input code ``c`` with exponent ``n``: an ``int`` for two integers,
        else an int64 array of their broadcast shape (``c`` and ``n`` arrays of the same shape,
        or one ``n``), computed on every core with the GIL released. ``out``, a C-contiguous
        int64 array of that shape, receives the codes instead of a new array (reusing it saves
        the allocation, as numpy's ``out=``); when an input is outside the model's domain the
        ``ValueError`` comes after some of it may have been written, as with numpy's ``out=``.
        A read-only ``out`` raises ``ValueError``; ``out`` may be an input (``eval(c, 64,
        out=c)``, ``c`` int64): the result is the same as into a fresh array."""
        if out is None and np.ndim(c) == 0 and np.ndim(n) == 0:
            return self._m.eval(_int(c, "c", np.int64), _int(n, "n", np.uint32))
        cs, ns, n_all, shape = self._pairs(c, n)
        if out is None:
            return self._m.eval_array(cs, ns, n_all).reshape(shape)
        if (
            not isinstance(out, np.ndarray)
            or out.dtype != np.int64
            or out.shape != shape
            or not out.flags.c_contiguous
        ):
            raise ValueError(
                f"out: expected a C-contiguous int64 array of shape {shape}, got "
                f"{getattr(out, 'dtype', type(out).__name__)} {getattr(out, 'shape', '')}"
            )
        flat = out.reshape(-1)
        # out may be an input (or overlap one): the inputs are read from a copy, so that the
        # result is the one a fresh out would get (the native half copies too when it sees the
        # overlap; this also covers views it cannot relate).
        if np.may_share_memory(flat, cs):
            cs = cs.copy()
        if ns is not None and np.may_share_memory(flat, ns):
            ns = ns.copy()
        self._m.eval_into(cs, ns, n_all, flat)
        return out

    def probes(self, c: IntOrArray, n: IntOrArray) -> Dict[str, Any]:
        """Every stage's value (``d``, ``t``, ``b``, ``sq1``.., ``coef``, ``out``) of the
        evaluations, each stage's overflow event under ``events`` (0 none, 1 wrapped,
        2 saturated, 3 zeroed: ``EVENTS``), ``cut`` (the cutoff forced the base to zero) and
        ``clamped`` (the input was above 1.0): ints and bools for two integers, else arrays of
        the broadcast shape."""
        scalar = np.ndim(c) == 0 and np.ndim(n) == 0
        cs, ns, n_all, shape = self._pairs(c, n)
        values, events, cut, clamped = self._m.probes_array(cs, ns, n_all)
        names = self.stages

        def shaped(a: np.ndarray) -> Any:
            return a.reshape(shape).item() if scalar else a.reshape(shape)

        out: Dict[str, Any] = {name: shaped(values[i]) for i, name in enumerate(names)}
        out["events"] = {name: shaped(events[i]) for i, name in enumerate(names)}
        out["cut"] = shaped(cut)
        out["clamped"] = shaped(clamped)
        return out

    def directed(self, seed: int = 1):
        """The directed cases ``specfx vectors`` always writes: every n's corner cases (the
        ends of the code range, 1.0 and above, every cutoff switch +-1 code), codes with a
        non-zero output, and the inputs on and next to every stage's rounding boundary,
        interleaved with ``seed``. Returns ``(n, c)``, two arrays."""
        return self._m.directed(_int(seed, "seed", np.uint64))

    def check(self) -> Dict[str, Any]:
        """The exhaustive check of every input code up to 1.0 and every n: the same figures as
        ``specfx check --json`` prints, as a dict (the GIL released while it runs)."""
        return json.loads(self._m.check_json())


class Machine:
    """The cycle model of ``specfx_top`` (docs/cycle.md), stepped in lockstep with a simulation:
    each call of ``cycle`` is one clock cycle.

    ``Machine(datapath, arch="pipelined")`` starts empty, as after reset.
    """

    def __init__(self, datapath: Datapath, arch: str = "pipelined") -> None:
        self._m = _Machine(datapath._m, arch)

    def cycle(self, input: Optional[tuple], out_ready: bool):
        """What the ports show during this cycle, given the input offered (``(c, n)`` when
        in_valid is high, else None) and out_ready: ``(in_ready, out)``, ``out`` being
        ``(input number, raw code)`` when out_valid is high, else None; then the clock edge
        (the input transfers when in_ready is high). A bad input (not a pair of integers, an n
        outside the set, a code outside the input format) raises ``ValueError`` and the machine
        does not move."""
        if input is not None:
            if not isinstance(input, (tuple, list)) or len(input) != 2:
                got = type(input).__name__
                if isinstance(input, (tuple, list)):
                    got = f"a {got} of {len(input)}"
                raise ValueError(f"input: expected None or a pair (c, n), got {got}")
            input = (_int(input[0], "c", np.int64), _int(input[1], "n", np.uint32))
        return self._m.cycle(input, bool(out_ready))

    def registers(self) -> List[tuple]:
        """The RTL core's registers now, named as in the RTL below ``u_core``:
        ``(name, width, value)``, value None when the register holds no valid data."""
        return self._m.registers()
