//! Which slaves a step holds and how (pressed, sticking or sliding): what
//! generalized-α reads to take a step by the trapezoidal rule
//! (`theory/trapezoidal.md`, "Impact steps").

use std::collections::BTreeMap;

use super::{ContactCorrection, ContactState, Key, Slave, STICK_MARGIN};

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
                let stick = mu > 0.0
                    && self
                        .active
                        .lambda_t
                        .get(k)
                        .is_some_and(|t| t[0].hypot(t[1]) < (1.0 - STICK_MARGIN) * mu * l);
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
                let tangential: BTreeMap<Key, [f64; 2]> = c.tangential.iter().copied().collect();
                c.active.iter().any(|(k, l)| {
                    let mu = self.setup.pairs[k.slave.pair].mu;
                    *l > threshold
                        && mu > 0.0
                        && tangential
                            .get(k)
                            .is_none_or(|t| t[0].hypot(t[1]) >= (1.0 - STICK_MARGIN) * mu * l)
                })
            }
            None => self
                .held()
                .iter()
                .any(|&(s, stick)| !stick && self.setup.pairs[s.pair].mu > 0.0),
        }
    }
}
