"""What the cocotb testbenches of specfx_top (test_specfx.py, test_live.py) need that differs
between the two cocotb releases they run under: cocotb 2.0.1 (target/cocotb-venv, Icarus
Verilog) and cocotb 1.8.1 (target/cocotb18-venv, Verilator 5.006, which cocotb 2.x does not
support).

Two things differ: starting the clock, and reaching a signal inside a generate block under
Verilator. Everything else the tests use is the same in both: `cocotb.test`, `RisingEdge`,
`ReadOnly`, `handle.value` (read and written), `len(handle)`, and of a value `is_resolvable`,
`int(value)` (its unsigned value) and `str(value)` (its bits, MSB first). A value's
`to_unsigned()` is 2.x only (1.x: `.integer`), so the tests use `int(value)`.
"""

import inspect
import re

import cocotb
from cocotb.clock import Clock


def start_clock(signal, period_ns):
    """Drives `signal` with a clock of `period_ns` ns, low for its first half period."""
    # The third argument is the time unit in both (`unit` in 2.x, `units` in 1.x).
    clock = Clock(signal, period_ns, "ns")
    started = clock.start(start_high=False)
    # cocotb 2.x: start() has started the clock's task; 1.x: it is a coroutine to start.
    if inspect.iscoroutine(started):
        cocotb.start_soon(started)
    return clock


def verilator_under_cocotb_1():
    """Whether this is cocotb 1.x running Verilator."""
    return cocotb.__version__.startswith("1.") and "verilator" in (cocotb.SIM_NAME or "").lower()


def signal_at(root, path):
    """The handle of a signal below `root` by its path in the RTL's names, e.g.
    `g_pipelined.u_core.g_square[2].y_q`; AttributeError, IndexError or KeyError when the
    design has no such signal."""
    if verilator_under_cocotb_1():
        # Verilator 5.006 shows a generate block as a vpiScope, of which cocotb 1.8 makes no
        # object ("VPI: Not able to map type vpiScope(84) to object"), so `root.g_pipelined`
        # fails. The signal itself is found by its full name, in Verilator's names (the block
        # `g_square[2]` is `g_square__BRA__2__KET__`); it is visible with --public-flat-rw.
        name = re.sub(r"\[(\d+)\]", r"__BRA__\1__KET__", path)
        return root._id(name, extended=False)
    h = root
    for part in path.split("."):
        if "[" in part:
            base, idx = part[:-1].split("[")
            h = getattr(h, base)[int(idx)]
        else:
            h = getattr(h, part)
    return h
