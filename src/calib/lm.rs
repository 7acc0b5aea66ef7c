//! Levenberg–Marquardt on the normal equations, for the calibration's
//! structure: every corner touches only the intrinsics and its own view's
//! six pose parameters, so `JᵀJ` (at most 9 + 6 × views a side) and `Jᵀr`
//! are summed corner by corner, without the Jacobian ever being stored.
//!
//! Why not the `levenberg-marquardt` crate: it factors the whole Jacobian
//! (pivoted QR, MINPACK's `lmder`) at every step. For 12 views of 188
//! corners that is a 4512 × 80 matrix; with the crate a calibration cost
//! 6.5 G instructions, 87 % of them in the factorisation, about 1 s on this
//! machine against the goal of 1 s. Here a step costs the sums (about 1 M
//! flops) and an 80 × 80 Cholesky: 0.45 G instructions a calibration
//! (callgrind, `examples/calib_count.rs solve`; docs/calibration.md).
//!
//! The step is Marquardt's: `(JᵀJ + λ diag(JᵀJ)) δ = −Jᵀr`, `λ` divided by
//! ten after a step that lowers the cost and multiplied by ten until one
//! does; the diagonal scaling makes it indifferent to the parameters' units
//! (pixels, millimetres, 10⁻⁴ mm⁻² and radians side by side).

use nalgebra::{DMatrix, DVector};

use super::CalibError;

/// A least-squares problem as the solver needs it.
pub trait Normal {
    fn params(&self) -> DVector<f64>;
    fn set_params(&mut self, x: &DVector<f64>);
    /// `‖r‖²` at the current parameters; `None` when they are out of reach
    /// (a corner out of the camera's view).
    fn cost(&self) -> Option<f64>;
    /// `(JᵀJ, Jᵀr)` at the current parameters.
    fn normal(&self) -> Option<(DMatrix<f64>, DVector<f64>)>;
}

/// How the minimisation went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Report {
    /// Cost evaluations (each a projection of every corner).
    pub evaluations: usize,
    pub iterations: usize,
}

/// Most steps taken.
const MAX_ITERATIONS: usize = 200;

/// Minimises `p`'s cost from its current parameters; leaves it at the
/// minimum. An error says why it stopped short.
pub fn minimize(p: &mut impl Normal) -> Result<Report, CalibError> {
    let stop = |why: &str| CalibError::NoConvergence { why: why.into() };
    let mut x = p.params();
    let mut cost = p
        .cost()
        .ok_or_else(|| stop("the starting values put a corner out of the camera's view"))?;
    let mut lambda = 1e-3;
    let mut evaluations = 1;
    for iteration in 0..MAX_ITERATIONS {
        let (a, g) = p
            .normal()
            .ok_or_else(|| stop("a corner left the camera's view"))?;
        if g.amax() <= 1e-14 * cost.max(1e-300) {
            return Ok(Report {
                evaluations,
                iterations: iteration,
            });
        }
        loop {
            let mut m = a.clone();
            for i in 0..m.nrows() {
                m[(i, i)] += lambda * a[(i, i)].max(1e-30);
            }
            let Some(step) = m.cholesky().map(|c| c.solve(&(-&g))) else {
                lambda *= 10.0;
                if lambda > 1e16 {
                    return Err(stop("the normal equations are singular"));
                }
                continue;
            };
            let trial = &x + &step;
            p.set_params(&trial);
            evaluations += 1;
            let new = p.cost().unwrap_or(f64::INFINITY);
            if new < cost {
                let small_step = step.norm() <= 1e-12 * (x.norm() + 1e-12);
                let small_gain = cost - new <= 1e-12 * cost;
                x = trial;
                cost = new;
                lambda = (lambda / 10.0).max(1e-15);
                if small_step || small_gain {
                    return Ok(Report {
                        evaluations,
                        iterations: iteration + 1,
                    });
                }
                break;
            }
            p.set_params(&x);
            lambda *= 10.0;
            if lambda > 1e16 {
                // No step lowers the cost any more: a minimum, to the
                // precision of the arithmetic.
                return Ok(Report {
                    evaluations,
                    iterations: iteration + 1,
                });
            }
        }
    }
    Err(CalibError::NoConvergence {
        why: format!("no minimum after {MAX_ITERATIONS} steps"),
    })
}
