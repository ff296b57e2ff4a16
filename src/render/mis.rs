//! Multiple importance sampling: the power heuristic with exponent 2 for one sample of each of
//! two strategies (Veach 1997, "Robust Monte Carlo methods for light transport simulation",
//! §9.2.4), which the path tracer and photon mapping's eye paths weigh light sampling and BSDF
//! sampling by.

/// The weight of a sample drawn with density `pdf` when `other` could have drawn it too.
pub fn power_heuristic(pdf: f64, other: f64) -> f64 {
    let (a, b) = (pdf * pdf, other * other);
    if a + b > 0.0 {
        a / (a + b)
    } else {
        0.0
    }
}
