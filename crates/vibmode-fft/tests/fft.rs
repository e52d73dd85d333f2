//! The planner's transforms: a case by hand and the inverse identity on random inputs.
use vibmode_fft::{forward, inverse, Complex, Planner};

/// A small case by hand: x = [1, 2, 3, 4] has X0 = 10, X1 = -2 + 2i, X2 = -2.
#[test]
fn four_points_by_hand() {
    let fwd = forward(4);
    let mut x = vec![1.0, 2.0, 3.0, 4.0];
    let mut spec = fwd.make_output_vec();
    fwd.process(&mut x, &mut spec).unwrap();
    let want = [
        Complex::new(10.0, 0.0),
        Complex::new(-2.0, 2.0),
        Complex::new(-2.0, 0.0),
    ];
    for (got, want) in spec.iter().zip(want) {
        assert!((got - want).norm() < 1e-12, "{got} != {want}");
    }
}

/// The identity inverse(forward(x)) = n x on random inputs of many lengths, odd, prime and
/// composite.
#[test]
fn inverse_undoes_forward_times_n() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    for n in [1usize, 2, 3, 5, 16, 17, 100, 127, 1000, 1024, 4099] {
        let x: Vec<f64> = (0..n)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect();
        let (fwd, inv) = (forward(n), inverse(n));
        let mut buf = x.clone();
        let mut spec = fwd.make_output_vec();
        fwd.process(&mut buf, &mut spec).unwrap();
        let mut back = inv.make_output_vec();
        inv.process(&mut spec, &mut back).unwrap();
        for (a, b) in x.iter().zip(&back) {
            assert!((a * n as f64 - b).abs() < 1e-9 * n as f64, "n = {n}");
        }
    }
}

/// A planner of one's own gives the same bits as the shared one.
#[test]
fn an_own_planner_gives_the_shared_planners_bits() {
    let x: Vec<f64> = (0..1000).map(|i| ((i * i) % 97) as f64 - 48.0).collect();
    let mut own = Planner::new();
    let (a, b) = (own.forward(1000), forward(1000));
    let (mut xa, mut xb) = (x.clone(), x);
    let (mut sa, mut sb) = (a.make_output_vec(), b.make_output_vec());
    a.process(&mut xa, &mut sa).unwrap();
    b.process(&mut xb, &mut sb).unwrap();
    assert_eq!(sa, sb);
    let inv = own.inverse(1000);
    let mut back = inv.make_output_vec();
    inv.process(&mut sa, &mut back).unwrap();
    assert!((back[1] / 1000.0 - (1.0 - 48.0)).abs() < 1e-9);
}
