//! Mode-shape comparisons: the modal assurance criterion and modal phase collinearity.

/// Complex modal assurance criterion `|a^H b|^2 / ((a^H a) (b^H b))` of two shapes given as
/// `[re, im]` per channel (one definition, shared with the clustering: `vibmode_modal::shapes`).
pub use vibmode_modal::shapes::mac;

/// Modal phase collinearity (Pappa, Elliott & Schenk 1993) of a complex mode shape given as
/// `[re, im]` per channel, in [0, 1]: 1 when the real and imaginary parts are collinear (a
/// real mode up to a complex factor), 0 for a shape whose parts are uncorrelated with equal
/// spread. With `x`, `y` the real and imaginary parts, each with its mean over the channels
/// removed, and `Sxx = x.x`, `Syy = y.y`, `Sxy = x.y`:
/// `MPC = ((Sxx - Syy)^2 + 4 Sxy^2) / (Sxx + Syy)^2`, the squared ratio
/// `((l1 - l2) / (l1 + l2))^2` of the eigenvalues of `[[Sxx, Sxy], [Sxy, Syy]]` (as pyOMA2's
/// `MPC`). 1 for a shape without spread (one channel, or all entries equal).
pub fn mpc(shape: &[[f64; 2]]) -> f64 {
    let n = shape.len();
    if n == 0 {
        return 1.0;
    }
    let mx = shape.iter().map(|v| v[0]).sum::<f64>() / n as f64;
    let my = shape.iter().map(|v| v[1]).sum::<f64>() / n as f64;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for v in shape {
        let (x, y) = (v[0] - mx, v[1] - my);
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    let total = sxx + syy;
    if total.is_nan() || total <= 0.0 || total.is_infinite() {
        return 1.0;
    }
    let d = sxx - syy;
    ((d * d + 4.0 * sxy * sxy) / (total * total)).clamp(0.0, 1.0)
}
