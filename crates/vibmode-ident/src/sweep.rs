//! The order sweep of one signal, whichever model it fits: the one place the sweep's model
//! choice is made (the analysis' identifier and the `sweep` command both call it).

use vibmode_core::SweepModel;

use crate::{ArMethod, ArmaModel, ArmaParams, IdentError};

/// The fits of `y` at every order of `orders`: ARMA(p, p) by [`crate::sweep_arma`] (warm-started
/// order to order, `params` for each fit) or AR(p) by `ar_method` (`params` unused). One result
/// per order, in the order given.
pub fn sweep_fits(
    y: &[f64],
    model: SweepModel,
    ar_method: ArMethod,
    orders: &[usize],
    params: &ArmaParams,
) -> Vec<Result<ArmaModel, IdentError>> {
    match model {
        SweepModel::Arma => crate::sweep_arma(y, orders, params),
        SweepModel::Ar => orders
            .iter()
            .map(|&p| crate::fit_ar(y, p, ar_method))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One result per order, each of its order; AR fits are the estimator's own.
    #[test]
    fn one_fit_per_order_of_the_model_asked() {
        // x_t = 1.2 x_{t-1} - 0.5 x_{t-2} + e_t from a fixed pseudo-random sequence
        let mut s = 12345u64;
        let mut e = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let mut y = vec![0.0; 2000];
        for t in 2..y.len() {
            y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + e();
        }
        let orders = [2, 4, 3];
        let params = ArmaParams::default();
        let ar = sweep_fits(&y, SweepModel::Ar, ArMethod::Burg, &orders, &params);
        assert_eq!(ar.len(), 3);
        for (f, &p) in ar.iter().zip(&orders) {
            let m = f.as_ref().unwrap();
            assert_eq!((m.p, m.q), (p, 0));
            assert_eq!(m.a, crate::fit_ar(&y, p, ArMethod::Burg).unwrap().a);
        }
        let arma = sweep_fits(&y, SweepModel::Arma, ArMethod::Burg, &orders, &params);
        let orders_fitted: Vec<(usize, usize)> = arma
            .iter()
            .map(|f| f.as_ref().map_or((0, 0), |m| (m.p, m.q)))
            .collect();
        assert_eq!(orders_fitted, vec![(2, 2), (4, 4), (3, 3)]);
        // the AR(2) coefficients, by hand: a = [1, -1.2, 0.5]
        let a2 = &ar[0].as_ref().unwrap().a;
        assert!(
            (a2[1] + 1.2).abs() < 0.05 && (a2[2] - 0.5).abs() < 0.05,
            "{a2:?}"
        );
    }
}
