//! The accumulators the analyses fold over the stream of every code and n: the running
//! maximum of a magnitude and where it happened ([`MaxAt`]), and the moments of a signed error
//! ([`Moments`]). Each merges with another of the same kind, so that work split by n and merged
//! in n order gives the same figures with any number of threads.

/// The running maximum of a magnitude and the input `(n, code)` where it first happened. A
/// NaN is never a maximum.
#[derive(Debug, Clone, Copy)]
pub(crate) struct MaxAt {
    /// The largest magnitude so far (-1 before the first).
    pub(crate) value: f64,
    /// Where it happened: `(n, raw code)`.
    pub(crate) at: (u32, i64),
}

impl MaxAt {
    /// Nothing seen yet.
    pub(crate) fn new() -> MaxAt {
        MaxAt {
            value: -1.0,
            at: (0, 0),
        }
    }

    /// Takes in the magnitude `v` (non-negative: the caller's absolute value) seen at `at`.
    #[inline]
    pub(crate) fn add(&mut self, v: f64, at: (u32, i64)) {
        if v > self.value {
            self.value = v;
            self.at = at;
        }
    }

    /// Takes in another maximum, from inputs that come after this one's.
    pub(crate) fn merge(&mut self, o: &MaxAt) {
        if o.value > self.value {
            *self = *o;
        }
    }
}

/// The moments of a signed error: its largest magnitude and where, its sum and the sum of its
/// squares.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moments {
    /// The largest magnitude.
    pub(crate) max: MaxAt,
    /// The sum.
    pub(crate) sum: f64,
    /// The sum of squares.
    pub(crate) sum_sq: f64,
}

impl Moments {
    /// Nothing seen yet.
    pub(crate) fn new() -> Moments {
        Moments {
            max: MaxAt::new(),
            sum: 0.0,
            sum_sq: 0.0,
        }
    }

    /// Takes in the error `e` seen at `at`.
    #[inline]
    pub(crate) fn add(&mut self, e: f64, at: (u32, i64)) {
        self.max.add(e.abs(), at);
        self.sum += e;
        self.sum_sq += e * e;
    }

    /// Takes in other moments, from inputs that come after these.
    pub(crate) fn merge(&mut self, o: &Moments) {
        self.max.merge(&o.max);
        self.sum += o.sum;
        self.sum_sq += o.sum_sq;
    }
}
