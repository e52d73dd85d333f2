//! Shared by the fleet's simulated end-to-end tests.
#![allow(dead_code)]

use vibmode_fleet::FleetConfig;

/// A faster analysis than the default (AR sweep to order 16) so several seeds run in seconds.
/// `FAR=0.05 cargo test ...` repeats a run at another false-alarm rate (docs/fleet.md).
pub fn config() -> FleetConfig {
    let mut c = FleetConfig::default();
    c.analysis.sweep.model = vibmode_analysis::SweepModel::Ar;
    c.analysis.sweep.order_max = 16;
    if let Some(v) = std::env::var("FAR").ok().and_then(|v| v.parse().ok()) {
        c.false_alarm_rate = v;
    }
    c
}
