//! Clustering with mode shapes: two modes at nearly the same frequency and damping (body heave
//! and pitch of a bus) are told apart by their shapes, over seeds; without shapes they merge.
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use vibmode_modal::shapes::mac;
use vibmode_modal::{find_invariant_modes, ClusterParams, ModeClass, PoleObservation};

/// Poles of two modes 3 % apart with damping 0.2, in every record and order, shapes jittered.
fn cloud(seed: u64) -> (Vec<PoleObservation>, [Vec<[f64; 2]>; 2]) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let heave = vec![[1.0, 0.0], [0.9, 0.0], [0.95, 0.0]];
    let pitch = vec![[1.0, 0.0], [-0.8, 0.0], [-0.85, 0.0]];
    let jf = Normal::new(0.0, 0.01).unwrap();
    let js = Normal::new(0.0, 0.05).unwrap();
    let mut poles = Vec::new();
    for record in 0..8 {
        for order in 2..=20 {
            for (f0, shape) in [(1.03, &pitch), (1.06, &heave)] {
                if rng.gen::<f64>() > 0.9 {
                    continue;
                }
                let mut p = PoleObservation::new(
                    f0 * (1.0 + jf.sample(&mut rng)),
                    0.2 * (1.0 + 2.0 * jf.sample(&mut rng)),
                    order,
                    record,
                    "all",
                );
                p.shape = Some(
                    shape
                        .iter()
                        .map(|x| [x[0] + js.sample(&mut rng), x[1] + js.sample(&mut rng)])
                        .collect(),
                );
                poles.push(p);
            }
        }
    }
    (poles, [pitch, heave])
}

#[test]
fn shapes_separate_modes_that_frequency_and_damping_cannot() {
    let orders: Vec<usize> = (2..=20).collect();
    for seed in 0..10 {
        let (poles, truth) = cloud(seed);
        let with = find_invariant_modes(&poles, 8, &orders, &ClusterParams::default()).unwrap();
        let structural: Vec<_> = with
            .iter()
            .filter(|m| m.class == ModeClass::Structural)
            .collect();
        assert_eq!(structural.len(), 2, "seed {seed}: {structural:?}");
        for t in &truth {
            let best = structural
                .iter()
                .map(|m| mac(m.shape.as_deref().unwrap(), t))
                .fold(0.0, f64::max);
            assert!(best > 0.99, "seed {seed}: best MAC {best}");
        }
        for m in &structural {
            let (median, lowest) = m.shape_mac.unwrap();
            assert!(
                median > 0.98 && lowest > 0.8 && lowest <= median,
                "{:?}",
                m.shape_mac
            );
        }
        let without = ClusterParams {
            shape_tol: 0.0,
            ..ClusterParams::default()
        };
        let merged = find_invariant_modes(&poles, 8, &orders, &without).unwrap();
        let n = merged
            .iter()
            .filter(|m| m.class == ModeClass::Structural)
            .count();
        assert_eq!(n, 1, "seed {seed}: without shapes the two modes merge");
    }
}
