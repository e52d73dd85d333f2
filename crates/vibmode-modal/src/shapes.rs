//! Complex mode shapes `[re, im]` per channel: the modal assurance criterion (MAC) and the mean
//! shape of a cluster.

/// Complex MAC `|a^H b|^2 / ((a^H a) (b^H b))` of two shapes (1 = the same shape up to a complex
/// factor, 0 = orthogonal). 0 when either is zero or their lengths differ.
pub fn mac(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    if a.len() != b.len() {
        return 0.0;
    }
    let (mut re, mut im, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        // conj(x) * y
        re += x[0] * y[0] + x[1] * y[1];
        im += x[0] * y[1] - x[1] * y[0];
        na += x[0] * x[0] + x[1] * x[1];
        nb += y[0] * y[0] + y[1] * y[1];
    }
    if na > 0.0 && nb > 0.0 {
        ((re * re + im * im) / (na * nb)).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Normalises a shape so that its largest-modulus entry is 1 + 0i (unchanged when zero).
pub fn normalise(shape: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let big = shape.iter().copied().fold([0.0_f64, 0.0], |b, x| {
        if x[0].hypot(x[1]) > b[0].hypot(b[1]) {
            x
        } else {
            b
        }
    });
    let n2 = big[0] * big[0] + big[1] * big[1];
    if n2 == 0.0 {
        return shape.to_vec();
    }
    // x / big = x * conj(big) / |big|^2
    shape
        .iter()
        .map(|x| {
            [
                (x[0] * big[0] + x[1] * big[1]) / n2,
                (x[1] * big[0] - x[0] * big[1]) / n2,
            ]
        })
        .collect()
}

/// The shape with each entry multiplied by its channel's real factor, normalised
/// ([`normalise`]): a shape identified from channels divided by their RMS, back in the channels'
/// units (`factors` = the RMS values). Entries without a factor are kept.
pub fn rescaled(shape: &[[f64; 2]], factors: &[f64]) -> Vec<[f64; 2]> {
    let back: Vec<[f64; 2]> = shape
        .iter()
        .enumerate()
        .map(|(i, x)| {
            let f = factors.get(i).copied().unwrap_or(1.0);
            [x[0] * f, x[1] * f]
        })
        .collect();
    normalise(&back)
}

/// Mean of shapes of one length: each is scaled by the complex factor that brings it closest (least
/// squares) to the first, the scaled shapes are averaged, and the mean is normalised
/// ([`normalise`]). `None` when there is no shape or the lengths differ.
pub fn mean_shape(shapes: &[&[[f64; 2]]]) -> Option<Vec<[f64; 2]>> {
    let first = normalise(shapes.first()?);
    let n = first.len();
    if n == 0 || shapes.iter().any(|s| s.len() != n) {
        return None;
    }
    let mut sum = vec![[0.0; 2]; n];
    for s in shapes {
        // alpha = (s^H first) / (s^H s)
        let (mut re, mut im, mut ss) = (0.0, 0.0, 0.0);
        for (x, y) in s.iter().zip(&first) {
            re += x[0] * y[0] + x[1] * y[1];
            im += x[0] * y[1] - x[1] * y[0];
            ss += x[0] * x[0] + x[1] * x[1];
        }
        if ss == 0.0 {
            continue;
        }
        let (ar, ai) = (re / ss, im / ss);
        for (acc, x) in sum.iter_mut().zip(s.iter()) {
            acc[0] += ar * x[0] - ai * x[1];
            acc[1] += ar * x[1] + ai * x[0];
        }
    }
    Some(normalise(&sum))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mac_by_hand() {
        let a = [[1.0, 0.0], [2.0, 0.0]];
        assert!((mac(&a, &a) - 1.0).abs() < 1e-15);
        // a complex multiple: (1 + 2i) a
        let b = [[1.0, 2.0], [2.0, 4.0]];
        assert!((mac(&a, &b) - 1.0).abs() < 1e-15);
        // orthogonal
        assert_eq!(mac(&a, &[[2.0, 0.0], [-1.0, 0.0]]), 0.0);
        // [1, 0] vs [1, 1]: |1|^2 / (1 * 2) = 0.5
        assert!((mac(&[[1.0, 0.0], [0.0, 0.0]], &[[1.0, 0.0], [1.0, 0.0]]) - 0.5).abs() < 1e-15);
        assert_eq!(mac(&a, &[[0.0, 0.0], [0.0, 0.0]]), 0.0);
        assert_eq!(mac(&a, &[[1.0, 0.0]]), 0.0);
    }

    #[test]
    fn rescaled_by_hand() {
        // [0.5, 1] with factors [4, 1] -> [2, 1] -> normalised [1, 0.5]
        let r = rescaled(&[[0.5, 0.0], [1.0, 0.0]], &[4.0, 1.0]);
        assert_eq!(r, vec![[1.0, 0.0], [0.5, 0.0]]);
    }

    #[test]
    fn mean_of_rotated_copies_is_the_shape() {
        let s = [[0.5, 0.1], [1.0, 0.0], [-0.3, 0.2]];
        let rot = |k: f64| -> Vec<[f64; 2]> {
            let (c, d): (f64, f64) = (k.cos() * 2.0, k.sin() * 2.0);
            s.iter()
                .map(|x| [c * x[0] - d * x[1], c * x[1] + d * x[0]])
                .collect()
        };
        let (a, b) = (rot(0.7), rot(-2.0));
        let m = mean_shape(&[&a, &b, &s]).unwrap();
        for (x, y) in m.iter().zip(&s) {
            assert!(
                (x[0] - y[0]).abs() < 1e-12 && (x[1] - y[1]).abs() < 1e-12,
                "{m:?}"
            );
        }
    }
}
