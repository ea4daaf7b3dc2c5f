//! The cycle model driven one cycle at a time, in lockstep with a simulation: what a
//! testbench's scoreboard asks each cycle (through the C ABI's DPI-C functions) is what
//! `specfx_top`'s ports must show, given this cycle's `in_valid` and `out_ready`.

use crate::cycle::{Arch, Folded, Item, Machine, Pipelined, RegisterView};
use crate::error::Error;
use crate::pipeline::Datapath;

/// Either machine, behind one type.
#[derive(Debug, Clone)]
enum Any {
    Pipelined(Pipelined),
    Folded(Folded),
}

/// A cycle model stepped by a testbench: [`Lockstep::cycle`] once per clock cycle.
#[derive(Debug, Clone)]
pub struct Lockstep {
    machine: Any,
    /// The next input's sequence number.
    tag: u64,
}

/// What `specfx_top`'s ports show during one cycle, by the cycle model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ports {
    /// `in_ready` (it may depend on this cycle's `out_ready`).
    pub in_ready: bool,
    /// `out_valid` and `out_data` with the sequence number (0, 1, ... in input order) of the
    /// input it belongs to: `None` when `out_valid` is low.
    pub out: Option<(u64, i64)>,
}

impl Lockstep {
    /// The machine of `arch`, empty, as after reset.
    pub fn new(dp: &Datapath, arch: Arch) -> Lockstep {
        let machine = match arch {
            Arch::Pipelined => Any::Pipelined(Pipelined::new(dp)),
            Arch::Folded => Any::Folded(Folded::new(dp)),
        };
        Lockstep { machine, tag: 0 }
    }

    /// One cycle: the ports during it, given the input offered (`Some((c_raw, n))` when
    /// `in_valid` is high) and `out_ready`; then the clock edge, which transfers the input when
    /// `in_ready` is high. An input outside the datapath's domain is refused before anything
    /// moves.
    ///
    /// # Examples
    /// ```
    /// use specfx::cycle::{lockstep::Lockstep, Arch};
    /// let dp = specfx::input::load_datapath("baseline", None).unwrap();
    /// let mut m = Lockstep::new(&dp, Arch::Pipelined);
    /// // One input in cycle 0; its output shows from cycle L = 8 on.
    /// let p = m.cycle(&dp, Some((dp.one_code(), 64)), true).unwrap();
    /// assert!(p.in_ready && p.out.is_none());
    /// for _ in 1..8 {
    ///     assert!(m.cycle(&dp, None, true).unwrap().out.is_none());
    /// }
    /// let coef = dp.constants_for(64).unwrap().coef_raw;
    /// assert_eq!(m.cycle(&dp, None, true).unwrap().out, Some((0, coef)));
    /// ```
    pub fn cycle(
        &mut self,
        dp: &Datapath,
        input: Option<(i64, u32)>,
        out_ready: bool,
    ) -> Result<Ports, Error> {
        let item = match input {
            Some((c_raw, n)) => {
                dp.constants_checked(n, "n")?;
                dp.check_code(c_raw, "c")?;
                let n_idx = dp.config().n.values().binary_search(&n).unwrap_or(0);
                Some(Item::new(dp, self.tag, n_idx, c_raw))
            }
            None => None,
        };
        let ports = match &self.machine {
            Any::Pipelined(m) => Ports {
                in_ready: m.in_ready(out_ready),
                out: m.output(),
            },
            Any::Folded(m) => Ports {
                in_ready: m.in_ready(out_ready),
                out: m.output(),
            },
        };
        let transfer = item.filter(|_| ports.in_ready);
        if transfer.is_some() {
            self.tag += 1;
        }
        match &mut self.machine {
            Any::Pipelined(m) => m.step(dp, transfer, out_ready),
            Any::Folded(m) => m.step(dp, transfer, out_ready),
        }
        Ok(ports)
    }

    /// Every register of the RTL core now (but its ports), under the RTL's names below the
    /// core instance `u_core` (`specfx_top`'s `g_pipelined.u_core` or `g_folded.u_core`):
    /// what a testbench compares with the DUT's internal registers to say which stage went
    /// wrong.
    pub fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        match &self.machine {
            Any::Pipelined(m) => m.registers(dp),
            Any::Folded(m) => m.registers(dp),
        }
    }
}
