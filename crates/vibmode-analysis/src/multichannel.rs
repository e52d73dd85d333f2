//! Stage 3b, multichannel identification: SSI-cov of all channels of each record at once, with
//! complex mode shapes; the poles pooled over records and orders and clustered with their shapes
//! (1 - MAC in the distance), the clusters classed with the line evidence, and matched to the
//! physical model by frequency and MAC.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
pub use vibmode_core::ShapedPole;
use vibmode_core::{
    ClusterParams, InvariantMode, ModeMatch, ModeUncertainty, MultichannelIdentifier,
    PoleObservation, PooledIdentification, ReferenceMode,
};
use vibmode_modal::{MATCH_MAC_MIN, MATCH_MAX_FREQ_DIFF_REL};
use vibmode_signal::Preprocessed;

use crate::lines::{LineStage, LineTrack};
use crate::AnalysisError;

/// Most groups of the jackknife over records (each group one more identification).
pub const JACKKNIFE_GROUPS: usize = 20;

/// Name of the pseudo-channel of the multichannel poles in the pole store and the clusters
/// (SSI-cov's [`MultichannelIdentifier::name`]).
pub const SSI_CHANNEL: &str = "ssi-cov";

/// Everything the multichannel identification found.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SsiAnalysis {
    /// Channels identified together, in the order of every shape.
    pub channels: Vec<String>,
    /// Orders identified.
    pub orders: Vec<usize>,
    /// Every pole kept (stable, complex, inside the valid band).
    pub poles: Vec<ShapedPole>,
    /// Clusters of the poles over records and orders, with mean shapes.
    pub invariant_modes: Vec<InvariantMode>,
    /// Physical-model modes matched by frequency and MAC, one to one.
    pub matches: Vec<ModeMatch>,
    /// Periodic lines of all the channels, tracked over the records.
    pub lines: Vec<LineTrack>,
    /// Records whose identification failed, with the message of the method's error (kept as
    /// text: it is what `results.json` reports).
    pub failed_records: Vec<(usize, String)>,
}

/// Stage 3b over the records: a [`MultichannelIdentifier`] (SSI-cov) on every active record
/// (or on the active records pooled), then clustering, classing and matching.
pub(crate) struct SsiStage<'a, M: MultichannelIdentifier> {
    pub pre: &'a [Preprocessed],
    pub active: &'a [Option<usize>],
    pub n_active: usize,
    /// The identification method.
    pub method: &'a M,
    /// Identify the active records together (one pooled identification) instead of one by one.
    pub pool_records: bool,
    pub cluster: &'a ClusterParams,
    pub drop_band_edge: bool,
    /// Each record's own first lag (pooled records only): records with `None` are left out.
    pub first_lags: Option<&'a [Option<usize>]>,
}

/// The identifications of [`SsiStage::poles`], for [`SsiStage::finish`].
pub(crate) struct SsiPoles<M: MultichannelIdentifier> {
    channels: Vec<String>,
    orders: Vec<usize>,
    scales: Vec<f64>,
    /// Per record (or one for the pool): its poles kept, or why its identification failed.
    per: Vec<Result<Vec<ShapedPole>, M::Error>>,
    jackknife: Option<JackknifeReps>,
}

/// The jackknife's repetitions: how many groups of records, and per group the poles identified
/// without it.
struct JackknifeReps {
    groups: usize,
    reps: Vec<Vec<ShapedPole>>,
}

impl<M: MultichannelIdentifier> SsiStage<'_, M> {
    /// RMS of each channel over the records used (1 where it is zero): SSI sees every channel
    /// divided by it, so that strong channels (the wheels) do not hide the modes of weak ones
    /// (the body); the shapes are scaled back.
    fn channel_scales(&self) -> Vec<f64> {
        let n_ch = self.pre.first().map_or(0, |p| p.recording.n_channels());
        (0..n_ch)
            .map(|c| {
                let (mut ss, mut n) = (0.0, 0usize);
                for (r, p) in self.pre.iter().enumerate() {
                    if self.active.get(r).copied().flatten().is_none() {
                        continue;
                    }
                    if let Some(ch) = p.recording.channels.get(c) {
                        let m = ch.samples.iter().sum::<f64>() / ch.samples.len().max(1) as f64;
                        ss += ch.samples.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
                        n += ch.samples.len();
                    }
                }
                let rms = (ss / n.max(1) as f64).sqrt();
                if rms > 0.0 && rms.is_finite() {
                    rms
                } else {
                    1.0
                }
            })
            .collect()
    }

    /// Record `p`'s channels, each divided by its scale.
    fn scaled(p: &Preprocessed, scales: &[f64]) -> Vec<Vec<f64>> {
        p.recording
            .channels
            .iter()
            .zip(scales)
            .map(|(c, s)| c.samples.iter().map(|v| v / s).collect())
            .collect()
    }

    /// The records used (each channel divided by its scale) pooled for one identification, and
    /// the first record's band; `None` when no record is used.
    fn pooled(
        &self,
        scales: &[f64],
    ) -> Result<Option<(M::Pooled, vibmode_core::BandLimit)>, M::Error> {
        let lag_of = |r: usize| self.first_lags.map(|l| l.get(r).copied().flatten());
        let (used, lags): (Vec<&Preprocessed>, Vec<Option<usize>>) = self
            .pre
            .iter()
            .enumerate()
            .filter(|(r, _)| self.active.get(*r).copied().flatten().is_some())
            .filter(|(r, _)| lag_of(*r) != Some(None))
            .map(|(r, p)| (p, lag_of(r).flatten()))
            .unzip();
        let Some(first) = used.first() else {
            return Ok(None);
        };
        let scaled: Vec<Vec<Vec<f64>>> = used.iter().map(|p| Self::scaled(p, scales)).collect();
        let segments: Vec<Vec<&[f64]>> = scaled
            .iter()
            .map(|rec| rec.iter().map(Vec::as_slice).collect())
            .collect();
        let lags: Option<Vec<usize>> = self
            .first_lags
            .is_some()
            .then(|| lags.into_iter().flatten().collect());
        let pooled = self
            .method
            .pool(&segments, first.band.fs_hz, lags.as_deref())?;
        Ok(Some((pooled, first.band)))
    }

    /// Standard deviations of the supported modes' frequency and damping by a delete-a-group
    /// jackknife over the records (at most [`JACKKNIFE_GROUPS`] groups of consecutive records):
    /// the pooled identification repeated without each group, each mode's median frequency and
    /// damping over the repetition's poles near it (within the clustering's radius, shapes with
    /// MAC at least `1 - shape_tol`, both shapes scaled as identified, as clustered), from the
    /// repetitions `reps` ([`Self::jackknife_reps`]). Nothing is set with fewer than 2 records or
    /// when a repetition failed (`reps` is then `None`).
    fn jackknife(&self, reps: Option<&JackknifeReps>, modes: &mut [InvariantMode], scales: &[f64]) {
        let inverse = inverse_scales(scales);
        let Some(JackknifeReps { groups, reps }) = reps else {
            return;
        };
        let groups = *groups;
        for m in modes.iter_mut().filter(|m| m.is_invariant()) {
            let Some(shape) = m.shape.as_deref() else {
                continue;
            };
            let scaled = vibmode_modal::shapes::rescaled(shape, &inverse);
            let tol = self
                .cluster
                .freq_tol_rel
                .max(self.cluster.freq_tol_per_damping * m.damping_ratio);
            let (mut fs, mut zs) = (Vec::new(), Vec::new());
            for rep in reps {
                let (f, z): (Vec<f64>, Vec<f64>) = rep
                    .iter()
                    .filter(|q| (q.frequency_hz / m.frequency_hz - 1.0).abs() <= tol)
                    .filter(|q| {
                        self.cluster.shape_tol <= 0.0
                            || vibmode_modal::shapes::mac(
                                &vibmode_modal::shapes::rescaled(&q.shape, &inverse),
                                &scaled,
                            ) >= 1.0 - self.cluster.shape_tol
                    })
                    .map(|q| (q.frequency_hz, q.damping_ratio))
                    .unzip();
                if !f.is_empty() {
                    fs.push(vibmode_modal::stats::median(&f));
                    zs.push(vibmode_modal::stats::median(&z));
                }
            }
            if fs.len() >= 2 {
                m.uncertainty = Some(ModeUncertainty {
                    frequency_std_hz: vibmode_ssi::jackknife_std(&fs),
                    damping_std: vibmode_ssi::jackknife_std(&zs),
                    replicates: fs.len(),
                    of: groups,
                    method: vibmode_core::UncertaintyMethod::Jackknife,
                });
            }
        }
    }

    /// The jackknife's repetitions of the pooled identification (see [`Self::jackknife`]), each
    /// without one group of records, their poles kept as the pool's; `None` with fewer than 2
    /// groups or when a repetition fails.
    fn jackknife_reps(
        &self,
        pooled: &M::Pooled,
        band: &vibmode_core::BandLimit,
        orders: &[usize],
        scales: &[f64],
    ) -> Option<JackknifeReps> {
        let groups = pooled.n_records().min(JACKKNIFE_GROUPS);
        if groups < 2 {
            return None;
        }
        let reps = pooled.jackknife(groups, orders).ok()?;
        Some(JackknifeReps {
            groups,
            reps: reps
                .into_iter()
                .map(|rep| self.kept(rep, 0, band, scales))
                .collect(),
        })
    }

    /// The poles below the valid band, as record `r`'s, with shapes scaled back.
    fn kept(
        &self,
        poles: Vec<ShapedPole>,
        r: usize,
        band: &vibmode_core::BandLimit,
        scales: &[f64],
    ) -> Vec<ShapedPole> {
        let f_max = if self.drop_band_edge {
            band.valid_max_hz()
        } else {
            band.fs_hz / 2.0
        };
        poles
            .into_iter()
            .filter(|q| q.frequency_hz < f_max)
            .map(|q| ShapedPole {
                record: r,
                shape: vibmode_modal::shapes::rescaled(&q.shape, scales),
                ..q
            })
            .collect()
    }

    fn record_poles(
        &self,
        r: usize,
        orders: &[usize],
        scales: &[f64],
    ) -> Result<Vec<ShapedPole>, M::Error> {
        let p = &self.pre[r];
        let scaled = Self::scaled(p, scales);
        let chans: Vec<&[f64]> = scaled.iter().map(Vec::as_slice).collect();
        let poles = self.method.identify_record(&chans, p.band.fs_hz, orders)?;
        Ok(self.kept(poles, r, &p.band, scales))
    }

    /// Identifies, clusters, classes (with the pool's own line tracks and `other_tracks`, those
    /// of the role pools; `own_tracks` when they are known already) and matches to `reference`:
    /// [`Self::poles`], then [`Self::finish`].
    pub fn run(
        &self,
        lines: &LineStage<'_>,
        own_tracks: Option<&[LineTrack]>,
        other_tracks: &[LineTrack],
        reference: &[ReferenceMode],
    ) -> Result<SsiAnalysis, AnalysisError> {
        self.finish(self.poles(), lines, own_tracks, other_tracks, reference)
    }

    /// The identifications (of every active record, or of the pool and its jackknife
    /// repetitions): what needs neither the line evidence nor the other stages, so it can run
    /// beside them.
    pub fn poles(&self) -> SsiPoles<M> {
        let channels: Vec<String> = self
            .pre
            .first()
            .map(|p| {
                p.recording
                    .channels
                    .iter()
                    .map(|c| c.name.clone())
                    .collect()
            })
            .unwrap_or_default();
        let orders = self.method.orders(channels.len());
        let scales = self.channel_scales();
        let pooled = if self.pool_records {
            Some(self.pooled(&scales))
        } else {
            None
        };
        let per: Vec<Result<Vec<ShapedPole>, M::Error>> = if let Some(p) = &pooled {
            vec![match p {
                Ok(Some((p, band))) => p
                    .identify(&orders)
                    .map(|poles| self.kept(poles, 0, band, &scales)),
                Ok(None) => Ok(Vec::new()),
                Err(e) => Err(e.clone()),
            }]
        } else {
            // Only the records used: a stop's poles would be dropped below.
            (0..self.pre.len())
                .into_par_iter()
                .map(|r| match self.active.get(r).copied().flatten() {
                    Some(_) => self.record_poles(r, &orders, &scales),
                    None => Ok(Vec::new()),
                })
                .collect()
        };
        let jackknife = match &pooled {
            Some(Ok(Some((p, band)))) => self.jackknife_reps(p, band, &orders, &scales),
            _ => None,
        };
        SsiPoles {
            channels,
            orders,
            scales,
            per,
            jackknife,
        }
    }

    /// Clusters the poles, classes the clusters (as [`Self::run`] says) and matches them to
    /// `reference`.
    pub fn finish(
        &self,
        poles: SsiPoles<M>,
        lines: &LineStage<'_>,
        own_tracks: Option<&[LineTrack]>,
        other_tracks: &[LineTrack],
        reference: &[ReferenceMode],
    ) -> Result<SsiAnalysis, AnalysisError> {
        let SsiPoles {
            channels,
            orders,
            scales,
            per,
            jackknife,
        } = poles;
        let mut poles = Vec::new();
        let mut failed_records = Vec::new();
        for (r, out) in per.into_iter().enumerate() {
            match out {
                Ok(p) => poles.extend(p),
                // results.json keeps the failure's one-line message.
                Err(e) => failed_records.push((r, e.to_string())),
            }
        }
        let pooled_records = self.pool_records;
        let (obs, of_pole): (Vec<PoleObservation>, Vec<usize>) =
            observations(&poles, &scales, self.method.name(), |r| {
                if pooled_records {
                    Some(0)
                } else {
                    self.active.get(r).copied().flatten()
                }
            })
            .into_iter()
            .unzip();
        let n_records = if pooled_records { 1 } else { self.n_active };
        let mut invariant_modes = if orders.is_empty() || self.n_active == 0 {
            Vec::new()
        } else {
            let a = vibmode_modal::analyse_poles(&obs, n_records, &orders, self.cluster)?;
            let mut modes = a.modes;
            physical_shapes(&mut modes, &a.labels, &of_pole, &poles);
            modes
        };
        let all: Vec<usize> = (0..channels.len()).collect();
        let tracks = match own_tracks {
            Some(t) => t.to_vec(),
            None => lines.tracks(&all),
        };
        // The lines of the role pools count too: a line seen clearly on the sprung channels may
        // be lost among the wheels' response when all channels are merged.
        let mut known: Vec<LineTrack> = tracks.clone();
        known.extend(other_tracks.iter().cloned());
        lines.classify(&mut invariant_modes, &all, &known);
        self.jackknife(jackknife.as_ref(), &mut invariant_modes, &scales);
        let matches = if reference.is_empty() {
            Vec::new()
        } else {
            vibmode_modal::match_reference_shapes(
                &invariant_modes,
                reference,
                &channels,
                MATCH_MAX_FREQ_DIFF_REL,
                MATCH_MAC_MIN,
            )
        };
        Ok(SsiAnalysis {
            channels,
            orders,
            poles,
            invariant_modes,
            matches,
            lines: tracks,
            failed_records,
        })
    }
}

/// `1 / scale` of each channel: brings physical shapes back to the scaled channels SSI-cov saw.
fn inverse_scales(scales: &[f64]) -> Vec<f64> {
    scales.iter().map(|s| 1.0 / s).collect()
}

/// The poles as the clustering sees them, each in record `record_of(pole.record)` (`None`: left
/// out). Their shapes are those SSI-cov identified, each channel still divided by its scale
/// (`scales`, [`SsiStage::channel_scales`]): there every channel's estimation error is of one size
/// (its noise relative to its RMS), whereas in physical units the strong, noisy wheel channels
/// dominate the MAC, and the shape of a mode the body sensors see and the wheels barely do (the
/// bending, under the wheel-hop band) scatters with their noise from order to order and falls
/// apart into clusters too small to be supported.
fn observations(
    poles: &[ShapedPole],
    scales: &[f64],
    channel: &str,
    record_of: impl Fn(usize) -> Option<usize>,
) -> Vec<(PoleObservation, usize)> {
    let inverse = inverse_scales(scales);
    poles
        .iter()
        .enumerate()
        .filter_map(|(i, q)| {
            let mut o = PoleObservation::new(
                q.frequency_hz,
                q.damping_ratio,
                q.order,
                record_of(q.record)?,
                channel,
            );
            o.shape = Some(vibmode_modal::shapes::rescaled(&q.shape, &inverse));
            Some((o, i))
        })
        .collect()
}

/// Each cluster's mean shape and the (median, lowest) MAC of its poles' shapes with it, in the
/// channels' units (the clustering compared them scaled): `labels` are the clustering's, one per
/// observation, `of_pole` the pole of each observation.
fn physical_shapes(
    modes: &mut [InvariantMode],
    labels: &[Option<usize>],
    of_pole: &[usize],
    poles: &[ShapedPole],
) {
    for (k, m) in modes.iter_mut().enumerate() {
        let shapes: Vec<&[[f64; 2]]> = labels
            .iter()
            .zip(of_pole)
            .filter(|(l, _)| **l == Some(k))
            .filter_map(|(_, &i)| poles.get(i).map(|q| q.shape.as_slice()))
            .collect();
        let Some(mean) = vibmode_modal::shapes::mean_shape(&shapes) else {
            continue;
        };
        let mut macs: Vec<f64> = shapes
            .iter()
            .map(|s| vibmode_modal::shapes::mac(s, &mean))
            .collect();
        macs.sort_by(f64::total_cmp);
        let lowest = macs.first().copied().unwrap_or(0.0);
        m.shape_mac = Some((vibmode_modal::stats::median(&macs), lowest));
        m.shape = Some(mean);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use vibmode_core::ModeClass;

    /// A body mode seen by two body channels (RMS 1) and barely by four wheel channels (RMS 10,
    /// the wheels' identified components pure noise of the body's size in their units), in
    /// every order of a sweep: one pole per order, frequency and damping scattered a little.
    fn body_mode_poles(orders: &[usize], seed: u64) -> Vec<ShapedPole> {
        let mut state: u64 = 0x2545_f491_4f6c_dd1d ^ seed.wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        orders
            .iter()
            .map(|&order| {
                let mut shape: Vec<[f64; 2]> =
                    (0..4).map(|_| [2.0 * uniform(), 2.0 * uniform()]).collect();
                shape.push([1.0 + 0.05 * uniform(), 0.0]);
                shape.push([-1.0 + 0.05 * uniform(), 0.0]);
                ShapedPole {
                    record: 0,
                    order,
                    frequency_hz: 8.0 * (1.0 + 0.002 * uniform()),
                    damping_ratio: 0.03 * (1.0 + 0.1 * uniform()),
                    mpc: 1.0,
                    shape,
                }
            })
            .collect()
    }

    fn best_order_share(poles: &[ShapedPole], scales: &[f64], orders: &[usize]) -> f64 {
        let obs: Vec<PoleObservation> = observations(poles, scales, SSI_CHANNEL, Some)
            .into_iter()
            .map(|(o, _)| o)
            .collect();
        let modes = vibmode_modal::find_invariant_modes(&obs, 1, orders, &ClusterParams::default())
            .unwrap_or_default();
        modes
            .iter()
            .filter(|m| m.class == ModeClass::Structural)
            .map(|m| m.order_share)
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_body_mode_under_noisy_wheels_is_one_supported_cluster() {
        let orders: Vec<usize> = (1..=30).map(|k| 2 * k).collect();
        let scales = [10.0, 10.0, 10.0, 10.0, 1.0, 1.0];
        for seed in 1..=8 {
            let poles = body_mode_poles(&orders, seed);
            // Clustered as identified (wheels divided by 10): one cluster in nearly every order.
            let scaled = best_order_share(&poles, &scales, &orders);
            assert!(scaled >= 0.9, "seed {seed}: {scaled}");
            // The same poles compared in the channels' units (no scaling) fall apart: the
            // wheels' noise makes the MAC, and no cluster reaches `min_order_share`.
            let physical = best_order_share(&poles, &[1.0; 6], &orders);
            assert!(physical < 0.5, "seed {seed}: {physical}");
        }
    }
}
