"""cocotb testbench of specfx_top against a specfx vector directory and stimulus.

The Python twin of hdl_ref/tb/tb_specfx.v, for a cocotb flow: the same drive, the same cycle
numbering and the same checks (docs/cycle.md is the contract).

Environment:
  SPECFX_VECTORS   a vector directory written by `specfx vectors --out DIR` (manifest.json,
                   in_c.hex, in_n.hex, in_slope.hex, in_offset.hex, in_threshold.hex,
                   in_coef.hex, expected_out.hex; one hex word per line)
  SPECFX_STIMULUS  a directory written by `specfx hdl stimulus --vectors DIR --arch A
                   --seed S --bubble P --stall P --out STIM` (stim_valid.hex, stim_ready.hex,
                   expected_cycle.hex, stim.json) for the same vectors and the DUT's ARCH
  SPECFX_RESET_DATA  optional, 0 or 1: the DUT's RESET_DATA (default: read from the DUT's
                   parameter when the simulator shows it, else 0)
  SPECFX_SUMMARY   optional: a JSON file to write the verdict to (passed, failed, problems)

The DUT's parameters must be the configuration's (`specfx hdl params --vectors DIR --arch A
--format json [--reset-data]`); hdl_ref/cocotb/run.py sets them and runs this test.

Drive, during cycle t (cycle 0 is the first after the 4 reset edges): in_valid = (vectors
left) && stim_valid[t], out_ready = stim_ready[t] (both 1 past the end of the files); the
input ports show the next vector also while in_valid is low (zeros after the last).
Checks: on each output transfer, out_data against expected_out[i] and the cycle against
expected_cycle[i]; out_valid and out_data held while out_valid is high and out_ready low
(rule 5); with RESET_DATA = 1, out_data == 0 in cycle 0; no X or Z on in_ready or out_valid
in any cycle, nor on out_data while out_valid is high; no output after the last one (rule
4, for a few cycles); every output arrives (a timeout counts the missing ones as failed).
Every word is compared as its raw bits, masked to the port's width (signed formats are two's
complement; any width up to 64 bits and beyond). The first problems are logged as
`mismatch i=<index> n=<n> c=<in_c> got=<out_data> want=<expected> cycle=<got> want_cycle=<want>`
(hex words, with the signed value in parentheses for signed formats), and the test fails on
any problem.
"""

import json
import os
from pathlib import Path

import cocotb
from cocotb.triggers import ReadOnly, RisingEdge

from cocotb_compat import start_clock

# Ports of the vector directory the test reads, in manifest.json's names.
DRIVEN_PORTS = ("in_c", "in_slope", "in_offset", "in_threshold", "in_coef", "in_depth")
VECTOR_PORTS = DRIVEN_PORTS + ("in_n", "expected_out")
RESET_EDGES = 4  # rst is high for this many rising edges, as in tb_specfx.v
CLOCK_PERIOD_NS = 10
MAX_SHOWN = 10


class SetupError(Exception):
    """A vector or stimulus directory that cannot be used (not a DUT problem)."""


def read_hex_words(path, width, count=None):
    """The words of a `$readmemh` file (one hex word per line), each checked to fit `width`."""
    try:
        text = path.read_text()
    except OSError as e:
        raise SetupError(f"{path}: cannot read ({e.strerror})") from None
    words = []
    for line_no, line in enumerate(text.splitlines(), start=1):
        token = line.split("//", 1)[0].strip()
        if not token:
            continue
        try:
            value = int(token, 16)
        except ValueError:
            raise SetupError(f"{path}:{line_no}: not a hex word: {token!r}") from None
        if value >> width:
            raise SetupError(f"{path}:{line_no}: {token} does not fit {width} bits")
        words.append(value)
    if count is not None and len(words) != count:
        raise SetupError(f"{path}: {len(words)} words, want {count}")
    return words


def read_json(path):
    try:
        return json.loads(path.read_text())
    except OSError as e:
        raise SetupError(f"{path}: cannot read ({e.strerror})") from None
    except ValueError as e:
        raise SetupError(f"{path}: not JSON ({e})") from None


class Port:
    """A manifest port: its name, width and signedness, and one word per vector."""

    def __init__(self, name, width, signed, words):
        self.name = name
        self.width = width
        self.signed = signed
        self.words = words

    def show(self, word):
        """A raw word as the vector files write it, with its signed value when signed."""
        text = f"{word:0{(self.width + 3) // 4}x}"
        if self.signed and word >> (self.width - 1):
            text += f" ({word - (1 << self.width)})"
        return text


class Vectors:
    """A vector directory and its stimulus, read and cross-checked."""

    def __init__(self, vectors_dir, stim_dir):
        manifest = read_json(vectors_dir / "manifest.json")
        try:
            self.n_vectors = int(manifest["n_vectors"])
            by_name = {p["name"]: p for p in manifest["ports"]}
        except (KeyError, TypeError, ValueError):
            raise SetupError(
                f"{vectors_dir / 'manifest.json'}: no n_vectors or ports list"
            ) from None
        self.ports = {}
        for name in VECTOR_PORTS:
            if name not in by_name:
                raise SetupError(f"{vectors_dir / 'manifest.json'}: no port {name}")
            try:
                width, signed = int(by_name[name]["width"]), bool(by_name[name]["signed"])
            except (KeyError, TypeError, ValueError):
                raise SetupError(
                    f"{vectors_dir / 'manifest.json'}: port {name} has no width or signed"
                ) from None
            words = read_hex_words(vectors_dir / f"{name}.hex", width, self.n_vectors)
            self.ports[name] = Port(name, width, signed, words)

        self.stim = read_json(stim_dir / "stim.json")
        try:
            self.n_cycles = int(self.stim["n_cycles"])
            stim_vectors = int(self.stim["n_vectors"])
            self.arch = str(self.stim["arch"])
        except (KeyError, TypeError, ValueError):
            raise SetupError(f"{stim_dir / 'stim.json'}: no n_cycles, n_vectors or arch") from None
        if stim_vectors != self.n_vectors:
            raise SetupError(
                f"{stim_dir / 'stim.json'} is for {stim_vectors} vectors, the vector directory "
                f"has {self.n_vectors}: write it with specfx hdl stimulus --vectors {vectors_dir}"
            )
        self.stim_valid = read_hex_words(stim_dir / "stim_valid.hex", 1, self.n_cycles)
        self.stim_ready = read_hex_words(stim_dir / "stim_ready.hex", 1, self.n_cycles)
        self.expected_cycle = read_hex_words(
            stim_dir / "expected_cycle.hex", 32, self.n_vectors
        )
        # Cycles watched after the last output for an extra one (rule 4): longer than any
        # input could take to come out; also the unit of the timeout's slack.
        latency = int(self.stim.get("latency", 0))
        self.settle = latency + int(self.stim.get("initiation_interval", 0)) + 2


def env_dir(name):
    value = os.environ.get(name)
    if not value:
        raise SetupError(f"set {name} (see the docstring of {Path(__file__).name})")
    path = Path(value)
    if not path.is_dir():
        raise SetupError(f"{name}={value}: not a directory")
    return path


def dut_parameter(dut, name):
    """The integer value of one of the DUT's parameters, or None when it cannot be read."""
    try:
        return int(getattr(dut, name).value)
    except Exception:  # noqa: BLE001 - a simulator may not show parameters at all
        return None


def reset_data_of(dut):
    """RESET_DATA: SPECFX_RESET_DATA, checked against the DUT's parameter when it shows."""
    in_dut = dut_parameter(dut, "RESET_DATA")
    value = os.environ.get("SPECFX_RESET_DATA", "")
    if value == "":
        return in_dut == 1
    if value not in ("0", "1"):
        raise SetupError(f"SPECFX_RESET_DATA={value}: want 0 or 1")
    if in_dut is not None and in_dut != int(value):
        raise SetupError(f"SPECFX_RESET_DATA={value} but the DUT has RESET_DATA = {in_dut}")
    return value == "1"


def check_port_widths(dut, vec):
    """Every driven port and out_data must be as wide as the manifest says."""
    wrong = []
    for name in DRIVEN_PORTS + ("expected_out",):
        handle_name = "out_data" if name == "expected_out" else name
        got = len(getattr(dut, handle_name))
        want = vec.ports[name].width
        if got != want:
            wrong.append(f"{handle_name} is {got} bits, the vectors' {name} {want}")
    if wrong:
        raise SetupError(
            "the DUT's parameters are not the vectors' configuration: "
            + "; ".join(wrong)
            + " (set them from specfx hdl params --vectors DIR --format json)"
        )
    arch = dut_parameter(dut, "ARCH")
    want_arch = {"pipelined": 0, "folded": 1}.get(vec.arch)
    if arch is not None and want_arch is not None and arch != want_arch:
        raise SetupError(
            f"the stimulus is for {vec.arch} but the DUT has ARCH = {arch}"
        )


class Checker:
    """Counts passed vectors and problems; keeps the first problems' lines."""

    def __init__(self, log):
        self.log = log
        self.passed = 0
        self.failed = 0
        self.problems = []

    def fail(self, line, count=1):
        self.failed += count
        if len(self.problems) < MAX_SHOWN:
            self.problems.append(line)
            self.log.error("%s", line)


def logic_text(value, width):
    """A 4-state value as hex when every bit is 0 or 1, else as its bits."""
    if value.is_resolvable:
        return f"{int(value):0{(width + 3) // 4}x}"
    return f"{value}"


@cocotb.test()
async def specfx_matches_vectors(dut):
    """specfx_top's outputs, their cycles and its handshake against the vectors and stimulus."""
    log = dut._log
    try:
        vec = Vectors(env_dir("SPECFX_VECTORS"), env_dir("SPECFX_STIMULUS"))
        check_port_widths(dut, vec)
        reset_data = reset_data_of(dut)
    except SetupError as e:
        write_summary({"passed": 0, "failed": 0, "problems": [f"setup: {e}"]})
        raise AssertionError(f"setup: {e}") from None

    n_vectors = vec.n_vectors
    ins = [vec.ports[name] for name in DRIVEN_PORTS]
    handles = [getattr(dut, name) for name in DRIVEN_PORTS]
    p_c, p_n, p_out = vec.ports["in_c"], vec.ports["in_n"], vec.ports["expected_out"]
    out_width = p_out.width
    last_expected = max(vec.expected_cycle, default=0)
    timeout = max(last_expected, vec.n_cycles) + 10 * vec.settle + 1000
    log.info(
        "%d vectors, %d stimulus cycles (%s, seed %s, bubble %s, stall %s), RESET_DATA = %d",
        n_vectors,
        vec.n_cycles,
        vec.arch,
        vec.stim.get("seed"),
        vec.stim.get("bubble"),
        vec.stim.get("stall"),
        int(reset_data),
    )

    def drive_inputs(idx):
        for port, handle in zip(ins, handles):
            handle.value = port.words[idx] if idx < n_vectors else 0

    chk = Checker(log)
    dut.rst.value = 1
    dut.in_valid.value = 0
    dut.out_ready.value = 0
    drive_inputs(0)
    start_clock(dut.clk, CLOCK_PERIOD_NS)
    for _ in range(RESET_EDGES):
        await RisingEdge(dut.clk)
    dut.rst.value = 0

    cycle = 0  # the current cycle (0 = first after reset)
    in_idx = 0  # next vector to offer
    out_idx = 0  # next output expected
    driven_idx = 0  # the vector on the input ports
    held = False  # the last cycle ended with out_valid && !out_ready
    held_data = None  # out_data at the end of the last cycle
    drain_left = None  # cycles still watched for extra outputs, once every output arrived
    while True:
        stimulus = cycle < vec.n_cycles
        in_valid = in_idx < n_vectors and (vec.stim_valid[cycle] if stimulus else 1) == 1
        out_ready = (vec.stim_ready[cycle] if stimulus else 1) == 1
        if driven_idx != in_idx:
            drive_inputs(in_idx)
            driven_idx = in_idx
        dut.in_valid.value = int(in_valid)
        dut.out_ready.value = int(out_ready)

        await ReadOnly()
        in_ready_bit = str(dut.in_ready.value)
        in_ready = in_ready_bit == "1"
        out_valid_bit = str(dut.out_valid.value)
        out_data = dut.out_data.value
        out_valid = out_valid_bit == "1"
        data_bits = str(out_data)
        # An X or Z is never read as 0 (tb_specfx.v's check).
        for name, bit in (("in_ready", in_ready_bit), ("out_valid", out_valid_bit)):
            if bit not in ("0", "1"):
                chk.fail(f"protocol: cycle {cycle}: {name}={bit}, an X or Z")
        if out_valid and not out_data.is_resolvable:
            chk.fail(
                f"protocol: cycle {cycle}: out_data={logic_text(out_data, out_width)} while "
                "out_valid is high, an X or Z"
            )

        if reset_data and cycle == 0 and data_bits != "0" * out_width:
            chk.fail(
                f"protocol: out_data={logic_text(out_data, out_width)} after reset with "
                "RESET_DATA=1, want 0"
            )
        if held and (not out_valid or data_bits != str(held_data)):
            chk.fail(
                f"protocol: out_valid/out_data changed while stalled, cycle={cycle} "
                f"(out_valid={out_valid_bit}, out_data={logic_text(out_data, out_width)}, "
                f"held {logic_text(held_data, out_width)})"
            )
        held = out_valid and not out_ready
        held_data = out_data
        if in_valid and in_ready:
            in_idx += 1
        if out_valid and out_ready:
            if out_idx < n_vectors:
                want = p_out.words[out_idx]
                want_cycle = vec.expected_cycle[out_idx]
                if (
                    out_data.is_resolvable
                    and int(out_data) == want
                    and cycle == want_cycle
                ):
                    chk.passed += 1
                else:
                    got = (
                        p_out.show(int(out_data))
                        if out_data.is_resolvable
                        else data_bits
                    )
                    chk.fail(
                        f"mismatch i={out_idx} n={p_n.words[out_idx]} "
                        f"c={p_c.show(p_c.words[out_idx])} got={got} want={p_out.show(want)} "
                        f"cycle={cycle} want_cycle={want_cycle}"
                    )
            else:
                chk.fail(
                    f"unexpected output {out_idx} got={logic_text(out_data, out_width)} "
                    f"cycle={cycle} (every input's output already arrived)"
                )
            out_idx += 1
            if out_idx == n_vectors:
                drain_left = vec.settle
        if drain_left is not None:
            if drain_left == 0:
                break
            drain_left -= 1
        if n_vectors == 0:
            break
        if cycle >= timeout and out_idx < n_vectors:
            i = out_idx
            chk.fail(
                f"timeout at cycle {cycle}: {out_idx} of {n_vectors} outputs arrived; first "
                f"missing i={i} n={p_n.words[i]} c={p_c.show(p_c.words[i])} "
                f"want={p_out.show(p_out.words[i])} want_cycle={vec.expected_cycle[i]}",
                count=n_vectors - out_idx,
            )
            break
        await RisingEdge(dut.clk)
        cycle += 1

    verdict = f"{chk.passed} passed, {chk.failed} failed"
    log.info("%s (%d cycles)", verdict, cycle + 1)
    write_summary(
        {
            "passed": chk.passed,
            "failed": chk.failed,
            "n_vectors": n_vectors,
            "arch": vec.arch,
            "problems": chk.problems,
        }
    )
    if n_vectors == 0:
        raise AssertionError("the vector directory holds no vector: nothing was checked")
    if chk.failed:
        shown = "\n  ".join(chk.problems)
        raise AssertionError(f"{verdict}; the first problems:\n  {shown}")
    assert chk.passed == n_vectors, verdict


def write_summary(summary):
    path = os.environ.get("SPECFX_SUMMARY")
    if path:
        Path(path).write_text(json.dumps(summary, indent=2) + "\n")
