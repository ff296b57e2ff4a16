//! Exact degree elevation of a Bézier segment to a cubic: a curve of degree `n` is one of
//! degree `n + 1` whose points are `Q_i = i/(n+1) · P_{i−1} + (1 − i/(n+1)) · P_i` (Forrest
//! 1972; Piegl & Tiller, *The NURBS Book*, §5.5, eq. 5.36), applied until the degree is 3. So a
//! surface of degree 1 or 2 along an axis becomes bicubic patches that are the same surface,
//! parameter for parameter.

use glam::{DVec3, DVec4};

/// What knot insertion and elevation blend: a point (a rational one in homogeneous form,
/// `(w x, w y, w z, w)`), or a row of points converted together.
pub trait Lerp: Copy {
    /// `self · (1 − a) + other · a`.
    fn lerp_to(self, other: Self, a: f64) -> Self;
}

impl Lerp for DVec3 {
    fn lerp_to(self, other: Self, a: f64) -> Self {
        self * (1.0 - a) + other * a
    }
}

impl Lerp for DVec4 {
    fn lerp_to(self, other: Self, a: f64) -> Self {
        self * (1.0 - a) + other * a
    }
}

impl<T: Lerp, const N: usize> Lerp for [T; N] {
    fn lerp_to(self, other: Self, a: f64) -> Self {
        std::array::from_fn(|k| self[k].lerp_to(other[k], a))
    }
}

/// The four points of the cubic equal to the Bézier segment `q` of degree `q.len() − 1`
/// (1 to 3).
pub fn to_cubic<T: Lerp>(q: &[T]) -> [T; 4] {
    match *q {
        [a, b] => [a, a.lerp_to(b, 1.0 / 3.0), a.lerp_to(b, 2.0 / 3.0), b],
        [a, b, c] => [a, a.lerp_to(b, 2.0 / 3.0), b.lerp_to(c, 1.0 / 3.0), c],
        [a, b, c, d] => [a, b, c, d],
        _ => panic!(
            "a Bézier segment of degree 1 to 3 has 2 to 4 points, not {}",
            q.len()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bernstein evaluation of a segment of any degree (de Casteljau).
    fn eval(points: &[DVec3], t: f64) -> DVec3 {
        let mut d = points.to_vec();
        for r in 1..d.len() {
            for j in 0..d.len() - r {
                d[j] = d[j].lerp(d[j + 1], t);
            }
        }
        d[0]
    }

    #[test]
    fn elevated_segments_are_the_same_curve() {
        let p = [
            DVec3::new(0.3, -1.0, 2.0),
            DVec3::new(1.7, 0.4, -0.5),
            DVec3::new(-0.2, 2.5, 1.1),
        ];
        for n in [2, 3] {
            let cubic = to_cubic(&p[..n]);
            for k in 0..=100 {
                let t = k as f64 / 100.0;
                assert!(
                    (eval(&cubic, t) - eval(&p[..n], t)).length() < 1e-14,
                    "degree {} at {t}",
                    n - 1
                );
            }
        }
    }
}
