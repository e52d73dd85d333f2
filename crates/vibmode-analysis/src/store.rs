//! Stage 4, the pole store: every pole of every fit, by channel, and the observations the
//! clustering reads. In memory today; a database-backed store offers the same queries.

use vibmode_core::{PoleObservation, Role};

use vibmode_core::PoleOut;

/// Every pole that passed the filters, per channel.
#[derive(Clone, Debug, Default)]
pub struct PoleStore {
    channels: Vec<(String, Role, Vec<PoleOut>)>,
}

impl PoleStore {
    /// An empty store.
    pub fn new() -> Self {
        PoleStore::default()
    }

    /// Adds the poles of one channel (appended to those already stored for it).
    pub fn add(&mut self, channel: &str, role: Role, poles: &[PoleOut]) {
        match self.channels.iter_mut().find(|(n, _, _)| n == channel) {
            Some((_, _, v)) => v.extend_from_slice(poles),
            None => self
                .channels
                .push((channel.to_string(), role, poles.to_vec())),
        }
    }

    /// The poles of one channel.
    pub fn poles(&self, channel: &str) -> &[PoleOut] {
        self.channels
            .iter()
            .find(|(n, _, _)| n == channel)
            .map_or(&[], |(_, _, v)| v.as_slice())
    }

    /// Observations for the clustering of the channels accepted by `which`, with record indices
    /// renumbered by `active` (`None` = record left out, e.g. a stop).
    pub fn observations(
        &self,
        which: impl Fn(&str, Role) -> bool,
        active: &[Option<usize>],
    ) -> Vec<PoleObservation> {
        self.channels
            .iter()
            .filter(|(n, r, _)| which(n, *r))
            .flat_map(|(name, role, poles)| {
                poles.iter().filter_map(move |p| {
                    let record = active.get(p.record).copied().flatten()?;
                    Some(PoleObservation {
                        frequency_hz: p.frequency_hz,
                        damping_ratio: p.damping_ratio,
                        order: p.order,
                        record,
                        channel: name.clone(),
                        role: Some(*role),
                        shape: None,
                    })
                })
            })
            .collect()
    }
}
