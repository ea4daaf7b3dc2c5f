"""Tests of the specfx Python package against the command line (unittest, no other package).

`import specfx` evaluates exactly what `specfx vectors` writes: every vector of exhaustive
directories of configurations at the edges (one-bit stages, a 64-bit signed output, a signed
input, 63-bit inputs, every rounding and overflow mode), outputs, probes and constants;
`check()` gives what `specfx check --json` prints; bad input raises ValueError with the command
line's message; batch work releases the GIL; nothing crosses the boundary as a panic (a
read-only out=, an out= that is an input, integers out of range or floats, memory exhaustion).

Run by tests/hardware/python.rs with the virtual environment ./scripts/test makes (the wheel
installed): SPECFX names the specfx binary, SPECFX_CONFIGS the tests/configs directory.
"""

import json
import os
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy as np

import specfx

SPECFX = os.environ["SPECFX"]
CONFIGS = os.environ["SPECFX_CONFIGS"]

SIGNED_IN = 'name = "signed_in"\nn = "16..=24"\n[c]\nformat = "s2.14"\n[d]\nformat = "s3.14"\n'


def cli(*args):
    return subprocess.run([SPECFX, *args], capture_output=True, text=True)


def config(name):
    return name if name == "baseline" else os.path.join(CONFIGS, name)


class Vectors(unittest.TestCase):
    def check_dir(self, config_arg, *args):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "v")
            o = cli("vectors", "--config", config_arg, "--out", out, *args)
            self.assertEqual(o.returncode, 0, o.stderr)
            with open(os.path.join(out, "vectors.csv")) as f:
                header = [h.split(":")[0] for h in f.readline().strip().split(",")]
            rows = np.loadtxt(os.path.join(out, "vectors.csv"), delimiter=",", skiprows=1,
                              dtype=np.int64, ndmin=2)
            col = {name: rows[:, i] for i, name in enumerate(header)}
            # The model of the vector directory itself (its manifest's configuration).
            dp = specfx.Datapath(out)
            c, n = col["in_c"], col["in_n"]
            np.testing.assert_array_equal(dp.eval(c, n), col["expected_out"], config_arg)
            p = dp.probes(c, n)
            for stage in dp.stages[:-2]:
                np.testing.assert_array_equal(p[stage], col["probe_" + stage], stage)
            np.testing.assert_array_equal(p["out"], col["expected_out"])
            for nv in np.unique(n):
                k = dp.constants(int(nv))
                first = np.flatnonzero(n == nv)[0]
                self.assertEqual(k["slope"], col["in_slope"][first])
                self.assertEqual(k["offset"], col["in_offset"][first])
                self.assertEqual(k["threshold"] or 0, col["in_threshold"][first])
                self.assertEqual(k["coef"], col["in_coef"][first])
                self.assertEqual(k["depth"], col["in_depth"][first])
            # One row by scalar call, and one n for a whole array.
            self.assertEqual(dp.eval(int(c[0]), int(n[0])), col["expected_out"][0])
            same = n == n[0]
            np.testing.assert_array_equal(dp.eval(c[same], int(n[0])), col["expected_out"][same])
            return dp

    def test_the_vectors_of_configurations_at_the_edges(self):
        self.check_dir("baseline", "--cases", "exhaustive", "--n", "16,17,1024")
        self.check_dir(config("every_mode.toml"), "--cases", "exhaustive")
        self.check_dir(config("lint_narrowest.toml"), "--cases", "exhaustive")
        self.check_dir(config("conv_sym_k5.toml"), "--cases", "exhaustive", "--n", "32,1000")
        self.check_dir(config("wide_signed_out64.toml"), "--cases", "corner,random:5000")
        self.check_dir(config("lint_widest.toml"), "--cases", "corner,random:5000")
        # A per-n depth: constants(n)["depth"] is the in_depth column.
        self.check_dir(config("depth_steps_signed.toml"), "--cases", "corner,random:5000")
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "signed_in.toml")
            with open(path, "w") as f:
                f.write(SIGNED_IN)
            dp = self.check_dir(path, "--cases", "exhaustive")
        self.assertEqual(dp.formats["c"], "s2.14")
        # TOML text gives the same model as the file.
        text = specfx.Datapath.from_toml(SIGNED_IN)
        codes = np.arange(-32768, 32768)
        np.testing.assert_array_equal(text.eval(codes, 20), dp.eval(codes, 20))


class Shapes(unittest.TestCase):
    def test_shapes_and_integer_types(self):
        dp = specfx.Datapath("baseline", n="16..=20")
        self.assertEqual(dp.n, [16, 17, 18, 19, 20])
        c = np.arange(32000, 32768, dtype=np.int32).reshape(8, 96)
        n = np.full((8, 96), 18, dtype=np.uint16)
        a = dp.eval(c, n)
        self.assertEqual(a.shape, (8, 96))
        self.assertEqual(a.dtype, np.int64)
        np.testing.assert_array_equal(a, dp.eval(c, 18))
        # Broadcasting: a column of n against a row of c.
        b = dp.eval(np.arange(32760, 32769), np.array([[16], [20]]))
        self.assertEqual(b.shape, (2, 9))
        self.assertEqual(b[1, 3], dp.eval(32763, 20))
        # out=: written in place; an input outside the domain raises the error that names it
        # (out may then hold some outputs, as numpy's out=).
        buf = np.full((8, 96), -1, dtype=np.int64)
        self.assertIs(dp.eval(c, n, out=buf), buf)
        np.testing.assert_array_equal(buf, a)
        bad = c.copy()
        bad[7, 95] = 70000
        with self.assertRaises(ValueError) as e:
            dp.eval(bad, n, out=buf)
        self.assertIn("c[767] = 70000 is not a code of the input format u1.15", str(e.exception))
        with self.assertRaises(ValueError) as e:
            dp.eval(c, n, out=np.empty((8, 95), dtype=np.int64))
        self.assertIn("out: expected a C-contiguous int64 array of shape (8, 96)", str(e.exception))
        p = dp.probes(c, n)
        self.assertEqual(p["events"]["t"].shape, (8, 96))
        self.assertEqual(p["cut"].dtype, np.bool_)


class Errors(unittest.TestCase):
    def test_bad_input_raises_value_error_with_the_command_lines_message(self):
        o = cli("check", "--config", "no/such.toml")
        self.assertEqual(o.returncode, 2)
        line = o.stderr.strip().removeprefix("specfx: error: ")
        with self.assertRaises(ValueError) as e:
            specfx.Datapath("no/such.toml")
        self.assertEqual(str(e.exception), line)
        with self.assertRaises(ValueError) as e:
            specfx.Datapath.from_toml("k = 9")
        self.assertTrue(str(e.exception).startswith("config: "), str(e.exception))
        dp = specfx.Datapath()
        cases = [
            ((0, 7), "n = 7 is not in the configuration's exponent set 16..=1024"),
            ((65536, 16), "c = 65536 is not a code of the input format u1.15 (expected 0..=65535)"),
            ((np.array([0, -1]), 16), "c[1] = -1 is not a code of the input format u1.15 (expected 0..=65535)"),
            ((np.array([0, 1]), np.array([16, 3])), "n[1] = 3 is not in the configuration's exponent set 16..=1024"),
            ((np.array([0.5]), 16), "c: expected integer codes, got an array of float64"),
            ((0, -16), "n = -16 does not fit in uint32"),
            ((np.array([2**64 - 1], dtype=np.uint64), 16), "c = 18446744073709551615 does not fit in int64"),
        ]
        for args, message in cases:
            with self.assertRaises(ValueError) as e:
                dp.eval(*args)
            self.assertEqual(str(e.exception), message)
        with self.assertRaises(ValueError):
            dp.probes(np.array([1, 2, 3]), np.array([16, 17]))
        with self.assertRaises(ValueError):
            dp.constants(15)


# Run in a child Python: its address space limited (RLIMIT_AS) to what it uses plus 256 MiB
# once its inputs exist, every result too large must raise MemoryError (the process aborted on
# an allocation failure before), and the interpreter carries on.
MEMORY_SCRIPT = """
import resource
import numpy as np, specfx
dp = specfx.Datapath()
dp.eval(np.arange(100), 64)  # the worker threads started before the limit
c = np.zeros(2**27, np.int64)  # 1 GiB of address space, never touched
n = np.full(2**27, 64, np.uint32)
with open("/proc/self/status") as f:
    vm = next(int(l.split()[1]) * 1024 for l in f if l.startswith("VmSize:"))
resource.setrlimit(resource.RLIMIT_AS, (vm + (256 << 20), resource.RLIM_INFINITY))
calls = [
    lambda: dp.eval(c, 64),
    lambda: dp.eval(c, n),
    lambda: dp.probes(c[: 2**24], 64),
    lambda: dp.eval(c, 64, out=c),
    lambda: dp._m.eval_into(c, None, 64, c),
]
for i, call in enumerate(calls):
    try:
        call()
        print(i, "no error")
    except MemoryError:
        print(i, "MemoryError")
print("after", dp.eval(np.array([0, 32768]), 64).tolist() == [0, dp.constants(64)["coef"]])
"""


class Boundary(unittest.TestCase):
    """What crosses the boundary badly gets an exception an ``except Exception`` catches
    (never PyO3's PanicException), or, for an out= that is an input, the right answer."""

    def test_a_read_only_out_raises_value_error(self):
        dp = specfx.Datapath()
        c = np.arange(4, dtype=np.int64)
        frozen = np.zeros(4, dtype=np.int64)
        frozen.flags.writeable = False
        for out in [frozen, np.frombuffer(bytes(32), np.int64)]:
            with self.assertRaises(ValueError) as e:
                dp.eval(c, 64, out=out)
            self.assertEqual(str(e.exception), "out: output array is read-only")
            with self.assertRaises(ValueError) as e:
                dp._m.eval_into(c, None, 64, out)
            self.assertEqual(str(e.exception), "out: output array is read-only")
        np.testing.assert_array_equal(frozen, 0)

    def test_an_out_that_is_an_input_is_computed_in_place(self):
        dp = specfx.Datapath()
        one, coef = dp.one_code, dp.constants(64)["coef"]
        # With n = 64 and k = 4 the base (64/16)(c - 1) + 1 is at most 0 below c = 0.75
        # (code 24576): the output is 0 there; at c = 1.0 the lobe is 1: the output is coef.
        codes = np.concatenate([np.arange(0, 24576, 97), [24576], np.arange(24577, one, 5), [one]])
        fresh = dp.eval(codes, 64)
        np.testing.assert_array_equal(fresh[codes <= 24576], 0)
        self.assertEqual(fresh[-1], coef)
        c = codes.copy()
        self.assertIs(dp.eval(c, 64, out=c), c)
        np.testing.assert_array_equal(c, fresh)
        # A view of the input as out, and the native half given the very same array.
        c = codes.copy()
        dp.eval(c, 64, out=c.view())
        np.testing.assert_array_equal(c, fresh)
        c = codes.copy()
        dp._m.eval_into(c, None, 64, c)
        np.testing.assert_array_equal(c, fresh)
        # n read from out's own bytes (a uint32 view of its first half).
        ns = np.resize(np.array([16, 64, 1024], dtype=np.uint32), codes.size)
        want = dp.eval(codes, ns)
        self.assertEqual(want[-1], dp.constants(int(ns[-1]))["coef"])
        for native in [False, True]:
            out = np.zeros(codes.size, dtype=np.int64)
            n_view = out.view(np.uint32)[: codes.size]
            n_view[:] = ns
            if native:
                dp._m.eval_into(codes, n_view, 0, out)
            else:
                dp.eval(codes, n_view, out=out)
            np.testing.assert_array_equal(out, want)

    def test_integers_are_checked_never_truncated_or_overflowed(self):
        dp = specfx.Datapath()
        m = specfx.Machine(dp)
        cases = [
            (lambda: dp.constants(-16), "n = -16 does not fit in uint32"),
            (lambda: dp.constants(2**70), f"n = {2**70} does not fit in uint32"),
            (lambda: dp.constants(16.5), "n: expected an integer, got float"),
            (lambda: dp.constants(16.0), "n: expected an integer, got float"),
            (lambda: dp.constants("16"), "n: expected an integer, got str"),
            (lambda: dp.constants(True), "n: expected an integer, got bool"),
            (lambda: dp.constants(7), "n = 7 is not in the configuration's exponent set 16..=1024"),
            (lambda: dp.directed(-1), "seed = -1 does not fit in uint64"),
            (lambda: dp.directed(1.5), "seed: expected an integer, got float"),
            (lambda: dp.eval(16.5, 64), "c: expected an integer, got float"),
            (lambda: dp.eval(0, 2**40), f"n = {2**40} does not fit in uint32"),
            (lambda: dp.eval(2**63, 64), f"c = {2**63} does not fit in int64"),
            (lambda: m.cycle((100, -16), True), "n = -16 does not fit in uint32"),
            (lambda: m.cycle((100.5, 16), True), "c: expected an integer, got float"),
            (lambda: m.cycle((100, 16.5), True), "n: expected an integer, got float"),
            (lambda: m.cycle((1, 2, 3), True), "input: expected None or a pair (c, n), got a tuple of 3"),
            (lambda: m.cycle(5, True), "input: expected None or a pair (c, n), got int"),
            (lambda: m.cycle((100, 7), True), "n = 7 is not in the configuration's exponent set 16..=1024"),
            (lambda: m.cycle((70000, 16), True), "c = 70000 is not a code of the input format u1.15 (expected 0..=65535)"),
        ]
        for call, message in cases:
            with self.assertRaises(ValueError) as e:
                call()
            self.assertEqual(str(e.exception), message)
        # numpy integers and 0-d arrays are integers.
        self.assertEqual(dp.constants(np.uint16(64)), dp.constants(64))
        self.assertEqual(dp.constants(np.array(64))["n"], 64)
        # The failed cycles left the machine as it was: it runs like one that never saw them.
        twin = specfx.Machine(dp)
        for i in range(24):
            offered = (dp.one_code - 40 * i, 16 + i) if i % 3 else None
            self.assertEqual(m.cycle(offered, i % 4 != 3), twin.cycle(offered, i % 4 != 3), i)
        self.assertEqual(m.registers(), twin.registers())

    def test_memory_exhaustion_raises_memory_error(self):
        o = subprocess.run([sys.executable, "-c", MEMORY_SCRIPT], capture_output=True, text=True)
        self.assertEqual(o.returncode, 0, o.stderr)
        want = [f"{i} MemoryError" for i in range(5)] + ["after True"]
        self.assertEqual(o.stdout.splitlines(), want, o.stderr)


class Check(unittest.TestCase):
    def test_check_gives_the_clis_figures(self):
        o = cli("check", "--config", config("every_mode.toml"), "--n", "8..=20", "--json")
        self.assertEqual(o.returncode, 0, o.stderr)
        want = json.loads(o.stdout)
        got = specfx.Datapath(config("every_mode.toml"), n="8..=20").check()
        self.assertEqual(got, want)


class Gil(unittest.TestCase):
    def test_batch_work_releases_the_gil(self):
        dp = specfx.Datapath()
        c = np.tile(np.arange(0, 32769, dtype=np.int64), 200)
        n = np.resize(np.array(dp.n, dtype=np.uint32), c.size)
        done = threading.Event()
        ticks = 0

        def work():
            for _ in range(3):
                dp.eval(c, n)
            done.set()

        t = threading.Thread(target=work)
        start = time.perf_counter()
        t.start()
        while not done.is_set():
            ticks += 1
            time.sleep(0.001)
        t.join()
        elapsed = time.perf_counter() - start
        # A thread holding the GIL for the whole batch would leave this loop one tick or so.
        self.assertGreater(ticks, 10, f"{ticks} ticks in {elapsed:.2f} s")


if __name__ == "__main__":
    unittest.main()
