//! Which slaves a step holds and how (pressed, sticking or sliding): what
//! generalized-α reads to take a step by the trapezoidal rule
//! (`theory/trapezoidal.md`, "Impact steps").

use super::{sticks, ContactCorrection, ContactState, Slave};

impl ContactCorrection<'_> {
    /// The slaves the current multipliers hold (above the active threshold), each
    /// with whether it sticks (frictional pairs; `false` without friction), sorted.
    pub(super) fn held(&self) -> Vec<(Slave, bool)> {
        let values: Vec<f64> = self.active.lambda.values().copied().collect();
        let threshold = self.active_threshold(&values);
        let mut held: Vec<(Slave, bool)> = self
            .active
            .lambda
            .iter()
            .filter(|(_, l)| **l > threshold)
            .map(|(k, &l)| {
                let mu = self.setup.pairs[k.slave.pair].mu;
                // No tangential multiplier is no tangential force: sticking, as
                // `finish` counts it.
                let t = self.active.lambda_t.get(k).copied().unwrap_or([0.0; 2]);
                let stick = mu > 0.0 && sticks(mu, l, t);
                (k.slave, stick)
            })
            .collect();
        held.sort_unstable();
        held.dedup();
        held
    }

    /// Whether the iterate holds other slaves than the step's start did, or holds
    /// one that stuck sliding or one that slid sticking: a slave pressed that was
    /// free, or released, or a change between stick and slip (multipliers above
    /// the active threshold; slaves compared, so a slave passing from one master
    /// facet to the next is no change). Generalized-α takes such a step by the
    /// trapezoidal rule (`theory/trapezoidal.md`, "Impact steps").
    pub fn held_changed(&self) -> bool {
        self.held() != self.start.held
    }

    /// Whether a held slave slides under friction, at the start of the step
    /// (`committed`, before [`ContactCorrection::begin_step`]) or, with `None`, at
    /// the current iterate. Generalized-α takes a sliding step by the trapezoidal
    /// rule too: the friction force at the step's end does positive work on its
    /// alternating slip rate otherwise (`theory/trapezoidal.md`, "Impact steps").
    pub fn sliding(&self, committed: Option<&ContactState>) -> bool {
        if !self.setup.frictional {
            return false;
        }
        match committed {
            Some(c) => {
                let values: Vec<f64> = c.active.iter().map(|(_, l)| *l).collect();
                let threshold = self.active_threshold(&values);
                // Both lists are written in key order ([`ContactCorrection::finish`]).
                c.active.iter().any(|&(k, l)| {
                    let mu = self.setup.pairs[k.slave.pair].mu;
                    let t = c
                        .tangential
                        .binary_search_by_key(&k, |&(key, _)| key)
                        .map_or([0.0; 2], |i| c.tangential[i].1);
                    l > threshold && mu > 0.0 && !sticks(mu, l, t)
                })
            }
            None => self
                .held()
                .iter()
                .any(|&(s, stick)| !stick && self.setup.pairs[s.pair].mu > 0.0),
        }
    }
}
