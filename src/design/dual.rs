//! Forward-mode derivatives with sparse gradients: a number or a vector together with its
//! partial derivatives with respect to the few design parameters it depends on (a photon's
//! path meets at most 16 control points on each patch it crosses), each gradient a list of
//! `(parameter, derivative)` sorted by parameter.

use glam::DVec3;

/// A parameter's number.
pub type Param = u32;

/// A scalar and its sparse gradient.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct D1 {
    /// The value.
    pub v: f64,
    /// `∂v/∂θ_p` for each parameter `p` it depends on, sorted by `p`.
    pub g: Vec<(Param, f64)>,
}

/// A vector and its sparse gradient.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct D3 {
    /// The value.
    pub v: DVec3,
    /// `∂v/∂θ_p` for each parameter `p` it depends on, sorted by `p`.
    pub g: Vec<(Param, DVec3)>,
}

/// `a` and `b` merged by parameter: `f(a's entry, b's entry)` for every parameter in either.
pub fn merge<A: Copy + Default, B: Copy + Default, C>(
    a: &[(Param, A)],
    b: &[(Param, B)],
    f: impl Fn(A, B) -> C,
) -> Vec<(Param, C)> {
    let mut out = Vec::with_capacity(a.len().max(b.len()));
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let (pa, pb) = (a.get(i).map(|e| e.0), b.get(j).map(|e| e.0));
        match (pa, pb) {
            (Some(x), Some(y)) if x == y => {
                out.push((x, f(a[i].1, b[j].1)));
                i += 1;
                j += 1;
            }
            (Some(x), Some(y)) if x < y => {
                out.push((x, f(a[i].1, B::default())));
                i += 1;
            }
            (Some(x), None) => {
                out.push((x, f(a[i].1, B::default())));
                i += 1;
            }
            (_, Some(y)) => {
                out.push((y, f(A::default(), b[j].1)));
                j += 1;
            }
            (None, None) => break,
        }
    }
    out
}

impl D1 {
    /// A constant.
    pub fn constant(v: f64) -> Self {
        Self { v, g: Vec::new() }
    }

    /// `self + other`.
    pub fn add(&self, other: &D1) -> D1 {
        D1 {
            v: self.v + other.v,
            g: merge(&self.g, &other.g, |a, b| a + b),
        }
    }

    /// `self · other`.
    pub fn mul(&self, other: &D1) -> D1 {
        D1 {
            v: self.v * other.v,
            g: merge(&self.g, &other.g, |a, b| a * other.v + self.v * b),
        }
    }

    /// `k · self`.
    pub fn scale(&self, k: f64) -> D1 {
        D1 {
            v: self.v * k,
            g: self.g.iter().map(|&(p, x)| (p, x * k)).collect(),
        }
    }

    /// `√self` (`self.v > 0`).
    pub fn sqrt(&self) -> D1 {
        let r = self.v.sqrt();
        D1 {
            v: r,
            g: self.g.iter().map(|&(p, x)| (p, x / (2.0 * r))).collect(),
        }
    }
}

impl D3 {
    /// A constant.
    pub fn constant(v: DVec3) -> Self {
        Self { v, g: Vec::new() }
    }

    /// `self + other`.
    pub fn add(&self, other: &D3) -> D3 {
        D3 {
            v: self.v + other.v,
            g: merge(&self.g, &other.g, |a, b| a + b),
        }
    }

    /// `k · self`.
    pub fn scale(&self, k: f64) -> D3 {
        D3 {
            v: self.v * k,
            g: self.g.iter().map(|&(p, x)| (p, x * k)).collect(),
        }
    }

    /// `s · self` for a scalar with a gradient.
    pub fn scale_by(&self, s: &D1) -> D3 {
        D3 {
            v: self.v * s.v,
            g: merge(&self.g, &s.g, |a, b| a * s.v + self.v * b),
        }
    }

    /// `self · other`.
    pub fn dot(&self, other: &D3) -> D1 {
        D1 {
            v: self.v.dot(other.v),
            g: merge(&self.g, &other.g, |a, b| a.dot(other.v) + self.v.dot(b)),
        }
    }

    /// The derivative with respect to `p` (zero when it does not depend on `p`).
    pub fn d(&self, p: Param) -> DVec3 {
        self.g
            .binary_search_by_key(&p, |e| e.0)
            .map_or(DVec3::ZERO, |i| self.g[i].1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_follow_the_product_rule() {
        let a = D1 {
            v: 2.0,
            g: vec![(1, 1.0), (4, 3.0)],
        };
        let b = D1 {
            v: 5.0,
            g: vec![(2, 1.0), (4, -1.0)],
        };
        let ab = a.mul(&b);
        assert_eq!(ab.v, 10.0);
        assert_eq!(ab.g, vec![(1, 5.0), (2, 2.0), (4, 13.0)]);
        let r = D1 {
            v: 4.0,
            g: vec![(0, 8.0)],
        }
        .sqrt();
        assert_eq!((r.v, r.g.clone()), (2.0, vec![(0, 2.0)]));
    }
}
