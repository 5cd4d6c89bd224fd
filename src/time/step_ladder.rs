//! The steps an error-controlled run may take, and the choice among them
//! (`theory/adaptive.md`): the rungs `dt_max / 2^k` down to `dt_min`, so that each
//! size's factor can be kept and found again; after a step with the relative error
//! measure `η`, the next step is the largest rung below
//! `h · safety · (tol/η)^(1/(p+1))` (`p` the scheme's order, the local error going
//! as `h^(p+1)`), at most one rung up; a step whose `η` exceeds the tolerance is
//! retried at least one rung down, unless it is already at the floor.

/// The ladder and the controller's constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ladder {
    /// The top rung (s).
    pub dt_max: f64,
    /// The bottom rung: the largest `dt_max / 2^k` not below the given `dt_min`.
    pub dt_min: f64,
    /// The tolerance on the relative error measure of a step.
    pub tolerance: f64,
    /// The scheme's order `p` (backward Euler 1, the trapezoidal rule and
    /// generalized-α 2).
    pub order: u32,
}

/// What the controller makes of a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// The step stands; the next one is `next`.
    Accept {
        /// The next step's size (a rung).
        next: f64,
    },
    /// The step is taken back and tried again at `retry` (a lower rung).
    Reject {
        /// The size to try (a rung).
        retry: f64,
    },
    /// Above the tolerance at the bottom rung: the step stands (a run warns).
    Floor,
}

/// The safety factor on the predicted step.
const SAFETY: f64 = 0.9;

impl Ladder {
    /// The ladder from `dt_max` down to the largest rung not below `dt_min`.
    pub fn new(dt_max: f64, dt_min: f64, tolerance: f64, order: u32) -> Self {
        let mut bottom = dt_max;
        while 0.5 * bottom >= dt_min * (1.0 - 1e-12) {
            bottom *= 0.5;
        }
        Ladder {
            dt_max,
            dt_min: bottom,
            tolerance,
            order,
        }
    }

    /// The rung `k` of a size on the ladder (`dt_max / 2^k`).
    pub fn index(&self, h: f64) -> u32 {
        (self.dt_max / h).log2().round().max(0.0) as u32
    }

    /// The largest rung not above `h`, and not below the bottom.
    pub fn rung(&self, h: f64) -> f64 {
        let mut r = self.dt_max;
        while r > h * (1.0 + 1e-12) && 0.5 * r >= self.dt_min * (1.0 - 1e-12) {
            r *= 0.5;
        }
        r
    }

    /// The verdict on a step of size `h` (a rung) whose error measure is `eta`.
    pub fn judge(&self, h: f64, eta: f64) -> Verdict {
        let grow = if eta > 0.0 {
            SAFETY * (self.tolerance / eta).powf(1.0 / f64::from(self.order + 1))
        } else {
            f64::INFINITY
        };
        if eta <= self.tolerance {
            Verdict::Accept {
                next: self.rung((h * grow).min(2.0 * h)),
            }
        } else if h <= self.dt_min * (1.0 + 1e-12) {
            Verdict::Floor
        } else {
            Verdict::Reject {
                retry: self.rung((h * grow).min(0.5 * h)),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rungs_halve_from_the_top_to_the_floor() {
        let l = Ladder::new(1e-3, 1e-5, 1e-4, 1);
        // 1e-3 / 2^6 = 1.5625e-5 ≥ 1e-5 > 2^-7 of it.
        assert!((l.dt_min - 1.5625e-5).abs() < 1e-18);
        assert_eq!(l.rung(7e-4), 5e-4);
        assert_eq!(l.rung(5e-4), 5e-4);
        assert_eq!(l.rung(1e-2), 1e-3);
        assert_eq!(l.rung(1e-9), l.dt_min);
        assert_eq!(l.index(2.5e-4), 2);
    }

    #[test]
    fn the_next_step_follows_the_estimate_and_the_order() {
        let l = Ladder::new(1e-3, 1e-6, 1e-4, 1);
        let h = 2.5e-4;
        // Far below the tolerance: one rung up at most.
        assert_eq!(l.judge(h, 1e-9), Verdict::Accept { next: 5e-4 });
        // Just below it: 0.9 (tol/η)^(1/2) < 1, one rung down.
        assert_eq!(l.judge(h, 0.9e-4), Verdict::Accept { next: 1.25e-4 });
        // Above it by 100: (1/100)^(1/2) · 0.9 = 0.09, four rungs down (1/16).
        assert_eq!(l.judge(h, 1e-2), Verdict::Reject { retry: h / 16.0 });
        // Above it by a little: at least one rung down.
        assert_eq!(l.judge(h, 1.01e-4), Verdict::Reject { retry: 1.25e-4 });
        // At the floor the step stands.
        assert_eq!(l.judge(l.dt_min, 1.0), Verdict::Floor);
        // Second order: the same excess asks for less.
        let l2 = Ladder::new(1e-3, 1e-6, 1e-4, 2);
        assert_eq!(l2.judge(h, 1e-2), Verdict::Reject { retry: h / 8.0 });
    }
}
