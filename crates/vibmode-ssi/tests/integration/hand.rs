//! Hand-checkable cases: MAC and MPC of vectors whose values are known by construction, a
//! noise-free free decay of one known mode, and stabilisation labels of a constructed result.

use std::f64::consts::PI;

use vibmode_ssi::{
    mac, mpc, ssi_cov, stabilisation, SsiMode, SsiOrder, SsiParams, SsiResult, Stability,
    StabilityParams,
};

#[test]
fn mac_of_known_vectors() {
    let a = [[1.0, 0.5], [-2.0, 0.0], [0.3, -1.0]];
    assert!((mac(&a, &a) - 1.0).abs() < 1e-15);
    // Orthogonal (real): [1, 1, 0] and [1, -1, 5].
    let x = [[1.0, 0.0], [1.0, 0.0], [0.0, 0.0]];
    let y = [[1.0, 0.0], [-1.0, 0.0], [5.0, 0.0]];
    assert_eq!(mac(&x, &y), 0.0);
    // Complex-orthogonal: a^H b = 1*1 + conj(i)*1 ... [1, i] and [1, -i]: 1 + (-i)(-i) = 0.
    let p = [[1.0, 0.0], [0.0, 1.0]];
    let q = [[1.0, 0.0], [0.0, -1.0]];
    assert!(mac(&p, &q).abs() < 1e-15);
    // A complex multiple: b = (2 - 3i) a.
    let k = (2.0, -3.0);
    let b: Vec<[f64; 2]> = a
        .iter()
        .map(|v| [k.0 * v[0] - k.1 * v[1], k.0 * v[1] + k.1 * v[0]])
        .collect();
    assert!((mac(&a, &b) - 1.0).abs() < 1e-14, "{}", mac(&a, &b));
    // Half-way: [1, 0] against [1, 1]: |1|^2 / (1 * 2) = 0.5.
    assert!((mac(&[[1.0, 0.0], [0.0, 0.0]], &[[1.0, 0.0], [1.0, 0.0]]) - 0.5).abs() < 1e-15);
    // A zero vector gives 0.
    assert_eq!(mac(&[[0.0, 0.0], [0.0, 0.0]], &a[..2]), 0.0);
}

#[test]
fn mpc_of_known_vectors() {
    // Real vector: 1.
    assert_eq!(mpc(&[[1.0, 0.0], [-0.4, 0.0], [0.7, 0.0]]), 1.0);
    // A real vector times a complex factor (monophase): 1.
    let r = [1.0, -0.4, 0.7, 0.2];
    let c: Vec<[f64; 2]> = r.iter().map(|v| [0.6 * v, 0.8 * v]).collect();
    assert!((mpc(&c) - 1.0).abs() < 1e-15);
    // [1, i, -1, -i]: centred parts [1,0,-1,0] and [0,1,0,-1], Sxx = Syy = 2, Sxy = 0 -> 0.
    assert!(mpc(&[[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]).abs() < 1e-15);
    // [1, 0, i, 0]... centred x = [3/4, -1/4, -1/4, -1/4], y = [-1/4, -1/4, 3/4, -1/4]:
    // Sxx = Syy = 3/4, Sxy = -1/4 -> (0 + 4/16) / (3/2)^2 = 1/9.
    let m = mpc(&[[1.0, 0.0], [0.0, 0.0], [0.0, 1.0], [0.0, 0.0]]);
    assert!((m - 1.0 / 9.0).abs() < 1e-15, "{m}");
}

/// `y_t = Re(lambda^t)`, `lambda = exp(s / fs)`, long enough to decay to rounding error.
fn free_decay(f_hz: f64, zeta: f64, fs_hz: f64, n: usize) -> Vec<f64> {
    let w = 2.0 * PI * f_hz;
    let (sr, si) = (-zeta * w, w * (1.0 - zeta * zeta).sqrt());
    (0..n)
        .map(|t| {
            let t = t as f64 / fs_hz;
            (sr * t).exp() * (si * t).cos()
        })
        .collect()
}

/// One channel, noise free, one mode, order 2. The correlation estimator divides lag k by
/// `N - k`: for a free decay that has died out, the unnormalised sums satisfy the mode's
/// recursion exactly, and the factor `N/(N - k) ~ exp(k/N)` moves the pole from `lambda` to
/// `lambda exp(1/N)`, i.e. `Re(s)` by `+fs/N`: the damping ratio comes out low by
/// `fs / (N omega)` and the frequency by the relative `zeta fs / (N omega)` (the removed mean adds
/// terms of order `1/N^2`). The test checks both predictions to 2 % of the bias (and 1e-8
/// after removing it), at two lengths.
#[test]
fn free_decay_of_one_mode_at_order_2() {
    let fs = 50.0;
    for &(f, z) in &[(2.0, 0.05), (6.5, 0.02), (11.0, 0.1)] {
        for &n in &[50_000usize, 200_000] {
            let y = free_decay(f, z, fs, n);
            let params = SsiParams {
                block_rows: 10,
                order_min: 2,
                order_max: 2,
                ..SsiParams::default()
            };
            let r = ssi_cov(&[&y], fs, &params).unwrap();
            let modes = &r.orders[0].modes;
            assert_eq!(modes.len(), 1, "f {f} z {z} n {n}: {modes:?}");
            let m = &modes[0];
            let w = 2.0 * PI * f;
            let dz = fs / (n as f64 * w);
            let z_pred = z - dz;
            let f_pred = f * (1.0 - z * dz);
            eprintln!(
                "f {f} z {z} n {n}: freq err {:.3e} (pred {:.3e}), damping err {:.3e} (pred {:.3e})",
                m.frequency_hz - f,
                f_pred - f,
                m.damping_ratio - z,
                -dz
            );
            assert!(
                (m.damping_ratio - z_pred).abs() < 0.02 * dz + 1e-8,
                "f {f} z {z} n {n}: damping {} predicted {z_pred}",
                m.damping_ratio
            );
            assert!(
                (m.frequency_hz - f_pred).abs() < 0.02 * z * dz * f + 1e-8 * f,
                "f {f} z {z} n {n}: frequency {} predicted {f_pred}",
                m.frequency_hz
            );
            assert_eq!(m.shape, vec![[1.0, 0.0]]);
            assert_eq!(m.mpc, 1.0);
        }
    }
}

fn mode(f: f64, z: f64, shape: &[[f64; 2]]) -> SsiMode {
    SsiMode {
        frequency_hz: f,
        damping_ratio: z,
        shape: shape.to_vec(),
        mpc: mpc(shape),
    }
}

#[test]
fn stabilisation_labels_by_hand() {
    let s1 = [[1.0, 0.0], [0.5, 0.0]];
    let s2 = [[1.0, 0.0], [-0.5, 0.0]]; // MAC with s1: (1 - 0.25)^2 / 1.25^2 = 0.36
    let result = SsiResult {
        fs_hz: 50.0,
        block_rows: 10,
        singular_values: vec![],
        orders: vec![
            SsiOrder {
                order: 2,
                modes: vec![mode(2.0, 0.05, &s1)],
            },
            SsiOrder {
                order: 4,
                modes: vec![
                    mode(2.01, 0.051, &s1), // 0.5 % and 2 %: stable
                    mode(5.0, 0.05, &s1),   // nothing near 5 Hz: new
                ],
            },
            SsiOrder {
                order: 6,
                modes: vec![
                    mode(2.0, 0.06, &s1),    // damping 18 % off: frequency only
                    mode(4.98, 0.0502, &s2), // MAC 0.36: frequency and damping
                    mode(9.0, 0.05, &s1),    // new
                ],
            },
        ],
    };
    let labels = stabilisation(&result, &StabilityParams::default());
    assert_eq!(
        labels,
        vec![
            vec![Stability::New],
            vec![Stability::Stable, Stability::New],
            vec![
                Stability::Frequency,
                Stability::FrequencyDamping,
                Stability::New
            ],
        ]
    );
}
