"""cocotb testbench of specfx_top with a live scoreboard: random stimulus with backpressure,
expected values from specfx's model (`import specfx`) as inputs are accepted.

No vector files: the test draws its own inputs (the directed cases of `specfx vectors` first:
corners, codes above 1.0, cutoff switches, every stage's rounding boundaries; then random n
from the configuration's set and random codes), computes each input's expected output with
`specfx.Datapath.eval` when it transfers, queues it, and checks every output transfer against
the head of the queue. Every cycle, `specfx.Machine` (the cycle model, docs/cycle.md) says
what in_ready and out_valid must be and which input's output must be on the port, so every
output is also checked on its cycle.

An X or Z on in_ready or out_valid in any cycle, or on out_data while out_valid is high, is a
failure (a missing reset shows so in Icarus Verilog; it is never read as 0).

Every cycle it also compares every register of the core (`specfx_top.g_pipelined.u_core` or
`g_folded.u_core`) holding valid data with the cycle model's (`Machine.registers`, the RTL's
names): the first register that differs (e.g. `g_square[1].y_q`, the second squaring) is a
failure, reported once in a `stage:` line that names the stage that went wrong, also when every
output agrees (a register the outputs do not show yet, or a difference a later stage hides). Under Verilator the
registers are visible as run.py builds it (`--public-flat-rw`), and are found by their full
names (cocotb_compat.signal_at); the log says how many of the model's registers were found.

Environment (hdl_ref/cocotb/run.py --live sets it):
  SPECFX_CONFIG    the configuration, as specfx --config takes it (the same as the DUT's
                   parameters: `specfx hdl params --config C --arch A --format json`)
  SPECFX_ARCH      pipelined or folded (the DUT's ARCH)
  SPECFX_SEED, SPECFX_NVEC, SPECFX_BUBBLE, SPECFX_STALL   the stimulus: seed, random vectors
                   after the directed ones, probabilities of a bubble and of a stalled cycle in
                   the random cycles of the handshake pattern

The handshake pattern (docs/cycle.md, "The handshake pattern", as `specfx hdl stimulus` draws
it): a block of directed episodes (an output stalled from its first cycle for longer than an
initiation interval while inputs come back to back at the interval, a stall that ends on the
cycle a new input is offered, a one-cycle stall, a stall in a stream), each after a drain, then
4096 random cycles (bubbles drawn per cycle, stalls in bursts), repeated.
  SPECFX_RESET_DATA  optional, 1 when the DUT has RESET_DATA = 1: out_data must be 0 in cycle 0
  SPECFX_SUMMARY   optional: a JSON file to write the verdict to
"""

import json
import os
import random
from pathlib import Path

import cocotb
from cocotb.triggers import ReadOnly, RisingEdge

import specfx
from cocotb_compat import signal_at, start_clock

RESET_EDGES = 4
CLOCK_PERIOD_NS = 10
MAX_SHOWN = 10
PORTS = ("in_slope", "in_offset", "in_threshold", "in_coef", "in_depth")
# The core below specfx_top, by architecture.
CORE = {"pipelined": "g_pipelined.u_core", "folded": "g_folded.u_core"}


def env(name, default=None):
    value = os.environ.get(name, default)
    if value is None:
        raise AssertionError(f"setup: {name} is not set")
    return value


class Stimulus:
    """The inputs to drive: the directed cases, then random ones; each with its constants."""

    def __init__(self, dp, seed, nvec):
        self.dp = dp
        self.rng = random.Random(seed)
        n_dir, c_dir = dp.directed(seed)
        self.directed = list(zip(c_dir.tolist(), n_dir.tolist()))
        self.total = len(self.directed) + nvec
        self.drawn = 0
        codes = dp.input_codes
        self.lo, self.hi, self.one = codes.start, codes.stop - 1, dp.one_code
        self.ns = dp.n
        self.constants = {}

    def ports(self, n):
        """The per-n constants as specfx_top's ports take them (a ROM addressed by n)."""
        if n not in self.constants:
            k = self.dp.constants(n)
            self.constants[n] = (
                k["slope"],
                k["offset"],
                k["threshold"] or 0,
                k["coef"],
                k["depth"],
            )
        return self.constants[n]

    def next(self):
        if self.drawn < len(self.directed):
            c, n = self.directed[self.drawn]
        else:
            n = self.rng.choice(self.ns)
            kind = self.rng.randrange(4)
            if kind == 0:
                c = self.rng.randint(self.lo, self.hi)
            elif kind == 1:
                c = min(max(self.one + self.rng.randint(-2, 2), self.lo), self.hi)
            else:
                c = self.rng.randint(self.lo, self.one)
        self.drawn += 1
        return c, n


def timing(dp, arch):
    """The cycle model's latency and initiation interval: an input offered on every cycle
    into an empty machine, always ready; the latency is the cycle its first output shows, the
    interval the cycle its second input is accepted."""
    machine = specfx.Machine(dp, arch)
    item = (dp.one_code, dp.n[0])
    latency = interval = None
    for cycle in range(10_000):
        ready, out = machine.cycle(item, True)
        if ready and cycle > 0 and interval is None:
            interval = cycle
        if out is not None and latency is None:
            latency = cycle
        if latency is not None and interval is not None:
            return latency, interval
    raise AssertionError("setup: the cycle model gave no output")


class Handshake:
    """The handshake pattern: (offer, out_ready) per cycle (`specfx::cycle::stimulus::Handshake`)."""

    RANDOM_CYCLES = 4096

    def __init__(self, latency, ii, bubble, stall, rng):
        self.rng, self.bubble = rng, bubble
        burst = ii + 1
        self.start = stall / (stall + burst * (1 - stall)) if stall > 0 else 0.0
        self.burst_max = 2 * burst - 1
        self.burst_left = 0
        self.cycle = 0
        s = ii + 1
        episodes = [
            ({0, ii, 2 * ii, 3 * ii}, latency, s),
            ({0, latency + s}, latency, s),
            ({0, 1}, latency, 1),
            (set(range(2 * ii + 1)), latency + 1, s),
        ]
        self.block = []
        for offers, stall_at, stall_len in episodes:
            self.block += [(False, True)] * (latency + ii + 2)
            end = max(max(offers), stall_at + stall_len - 1)
            self.block += [
                (t in offers, not stall_at <= t < stall_at + stall_len) for t in range(end + 1)
            ]

    def next(self):
        phase = self.cycle % (len(self.block) + self.RANDOM_CYCLES)
        self.cycle += 1
        if phase < len(self.block):
            self.burst_left = 0
            return self.block[phase]
        offer = self.rng.random() >= self.bubble
        if self.burst_left > 0:
            self.burst_left -= 1
            ready = False
        elif self.rng.random() < self.start:
            self.burst_left = self.rng.randint(1, self.burst_max) - 1
            ready = False
        else:
            ready = True
        return offer, ready


def drive(dut, widths, item):
    c, n, constants = item
    dut.in_c.value = c & ((1 << widths["in_c"]) - 1)
    for name, v in zip(PORTS, constants):
        getattr(dut, name).value = v & ((1 << widths[name]) - 1)


async def reset(dut):
    dut.rst.value = 1
    dut.in_valid.value = 0
    dut.out_ready.value = 0
    for _ in range(RESET_EDGES):
        await RisingEdge(dut.clk)
    dut.rst.value = 0


@cocotb.test()
async def specfx_live_scoreboard(dut):
    """specfx_top on random stimulus, each output checked against specfx's model on its cycle."""
    log = dut._log
    dp = specfx.Datapath(env("SPECFX_CONFIG"))
    arch = env("SPECFX_ARCH")
    seed = int(env("SPECFX_SEED", "1"))
    bubble = float(env("SPECFX_BUBBLE", "0.2"))
    stall = float(env("SPECFX_STALL", "0.2"))
    reset_data = env("SPECFX_RESET_DATA", "0") == "1"
    stim = Stimulus(dp, seed, int(env("SPECFX_NVEC", "2000")))
    widths = {name: len(getattr(dut, name)) for name in ("in_c",) + PORTS}
    out_width = len(dut.out_data)
    mask = (1 << out_width) - 1
    machine = specfx.Machine(dp, arch)
    latency, interval = timing(dp, arch)
    handshake = Handshake(latency, interval, bubble, stall, random.Random(seed + 1))
    log.info("%d vectors (%d directed), %s, seed %d", stim.total, len(stim.directed), arch, seed)

    start_clock(dut.clk, CLOCK_PERIOD_NS)
    await reset(dut)
    handles = {}
    for name, _, _ in machine.registers():
        try:
            # A register below the core, e.g. `g_square[2].y_q`.
            handles[name] = signal_at(dut, f"{CORE[arch]}.{name}")
        except (AttributeError, IndexError, KeyError):
            # A register the RTL does not have: the cycle model's registers are the reference
            # RTL's; a modified RTL may differ, and then the outputs still say whether it is
            # right.
            pass
    log.info("%d of the cycle model's %d registers found in the core", len(handles),
             len(machine.registers()))
    first_register = None  # the first register that differed from the model's

    expected = []  # (c, n, constants, output) of the inputs that transferred, in order
    passed = failed = out_idx = 0
    problems = []
    pending = None  # the drawn input, held until it transfers
    held = None
    cycle = 0
    timeout = 1000 + stim.total * (dp.k + 6) * 8

    def fail(line):
        nonlocal failed
        failed += 1
        if len(problems) < MAX_SHOWN:
            problems.append(line)
            log.error("%s", line)

    while True:
        if pending is None and stim.drawn < stim.total:
            c, n = stim.next()
            pending = (c, n, stim.ports(n))
            drive(dut, widths, pending)
        offer, out_ready = handshake.next()
        in_valid = pending is not None and offer
        dut.in_valid.value = int(in_valid)
        dut.out_ready.value = int(out_ready)
        await ReadOnly()
        if first_register is None:
            for name, width, want in machine.registers():
                h = handles.get(name)
                if want is None or h is None:
                    continue
                got = str(h.value)
                if not set(got) <= {"0", "1"} or int(got, 2) != want & ((1 << width) - 1):
                    first_register = (
                        f"stage: the first register that differs from the model is {name} "
                        f"(cycle {cycle}: got {got}, the model {want & ((1 << width) - 1):x})"
                    )
                    # Always shown (not counted among the first problems shown).
                    failed += 1
                    problems.append(first_register)
                    log.error("%s", first_register)
                    break
        handshake_bits = {"in_ready": str(dut.in_ready.value), "out_valid": str(dut.out_valid.value)}
        for name, bit in handshake_bits.items():
            if bit not in ("0", "1"):
                fail(f"protocol: cycle {cycle}: {name}={bit}, an X or Z")
        in_ready = handshake_bits["in_ready"] == "1"
        out_valid = handshake_bits["out_valid"] == "1"
        data = dut.out_data.value
        if out_valid and not data.is_resolvable:
            fail(f"protocol: cycle {cycle}: out_data={data} while out_valid is high, an X or Z")
        m_ready, m_out = machine.cycle(pending[:2] if in_valid else None, out_ready)
        if in_ready != m_ready:
            fail(f"protocol: cycle {cycle}: in_ready={int(in_ready)}, the cycle model says {int(m_ready)}")
        if out_valid != (m_out is not None):
            fail(f"protocol: cycle {cycle}: out_valid={int(out_valid)}, the cycle model says {int(m_out is not None)}")
        if reset_data and cycle == 0 and str(data) != "0" * out_width:
            fail(f"protocol: out_data={data} after reset with RESET_DATA=1, want 0")
        if held is not None and (not out_valid or str(data) != held):
            fail(f"protocol: out_valid/out_data changed while stalled, cycle={cycle}")
        held = str(data) if out_valid and not out_ready else None
        if in_valid and in_ready:
            c, n, constants = pending
            expected.append((c, n, constants, dp.eval(c, n)))
            pending = None
        if out_valid and out_ready:
            if out_idx >= len(expected):
                fail(f"unexpected output at cycle {cycle}: no input is left")
            else:
                c, n, constants, want = expected[out_idx]
                on_cycle = m_out is not None and m_out[0] == out_idx
                if data.is_resolvable and int(data) == want & mask and on_cycle:
                    passed += 1
                else:
                    got = f"{int(data):x}" if data.is_resolvable else str(data)
                    fail(
                        f"mismatch i={out_idx} n={n} c={c} got={got} want={want & mask:x} "
                        f"cycle={cycle} (the cycle model "
                        f"{'agrees on the cycle' if on_cycle else 'expects it on another cycle'})"
                    )
            out_idx += 1
            if out_idx >= stim.total:
                break
        if cycle >= timeout:
            fail(f"timeout at cycle {cycle}: {out_idx} of {stim.total} outputs arrived")
            failed += stim.total - out_idx - 1
            break
        await RisingEdge(dut.clk)
        cycle += 1

    if failed and first_register is None:
        line = "stage: every register of the core agreed with the model"
        problems.append(line)
        log.error("%s", line)
    verdict = f"{passed} passed, {failed} failed"
    log.info("%s (%d cycles)", verdict, cycle + 1)
    path = os.environ.get("SPECFX_SUMMARY")
    if path:
        summary = {"passed": passed, "failed": failed, "n_vectors": stim.total,
                   "arch": arch, "problems": problems}
        Path(path).write_text(json.dumps(summary, indent=2) + "\n")
    if failed:
        raise AssertionError(verdict + "; the first problems:\n  " + "\n  ".join(problems))
    assert passed == stim.total, verdict
