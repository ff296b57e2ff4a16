//! Unit vectors in two numbers: the octahedral map (Meyer et al. 2010, "On floating-point
//! normal vectors"; Cigolle et al. 2014, "A survey of efficient representations for
//! independent unit vectors", §3.3). The sphere is projected onto the octahedron
//! `|x| + |y| + |z| = 1`, whose lower half is folded over the upper one into the square
//! `[-1, 1]²`.

use glam::{DVec3, Vec2};

/// The lower half's fold: where a point of the square's inside diamond goes outside it.
fn fold(x: f64, y: f64) -> (f64, f64) {
    let sign = |v: f64| if v >= 0.0 { 1.0 } else { -1.0 };
    ((1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y))
}

/// `v` (unit) as a point of `[-1, 1]²`.
pub fn encode(v: DVec3) -> (f64, f64) {
    let l1 = v.x.abs() + v.y.abs() + v.z.abs();
    let (x, y) = (v.x / l1, v.y / l1);
    if v.z >= 0.0 {
        (x, y)
    } else {
        fold(x, y)
    }
}

/// The unit vector of a point of `[-1, 1]²`.
pub fn decode(x: f64, y: f64) -> DVec3 {
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z >= 0.0 { (x, y) } else { fold(x, y) };
    DVec3::new(x, y, z).normalize()
}

/// `v` (unit) in two f32: within about 1e-7 radians.
pub fn encode_f32(v: DVec3) -> Vec2 {
    let (x, y) = encode(v);
    Vec2::new(x as f32, y as f32)
}

/// The unit vector of [`encode_f32`]'s pair.
pub fn decode_f32(e: Vec2) -> DVec3 {
    decode(e.x as f64, e.y as f64)
}

/// `v` (unit) in 32 bits, 16 for each coordinate: within about 1e-4 radians.
pub fn encode_u32(v: DVec3) -> u32 {
    let (x, y) = encode(v);
    let q = |c: f64| ((c.clamp(-1.0, 1.0) * 0.5 + 0.5) * 65535.0).round() as u32;
    q(x) | q(y) << 16
}

/// The unit vector of [`encode_u32`]'s bits.
pub fn decode_u32(bits: u32) -> DVec3 {
    let c = |q: u32| (q & 0xffff) as f64 / 65535.0 * 2.0 - 1.0;
    decode(c(bits), c(bits >> 16))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directions all over the sphere, the poles, the axes and the octahedron's edges come back
    /// within each encoding's precision.
    #[test]
    fn directions_come_back_within_their_precision() {
        let mut dirs = vec![
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::X,
            -DVec3::Y,
            -DVec3::Z,
            DVec3::new(1.0, 1.0, 0.0).normalize(),
            DVec3::new(-1.0, 0.0, -1.0).normalize(),
        ];
        for k in 0..2000 {
            // A spiral over the sphere.
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 2000.0;
            let phi = k as f64 * 2.399_963;
            let s = (1.0 - z * z).sqrt();
            dirs.push(DVec3::new(s * phi.cos(), s * phi.sin(), z));
        }
        for v in dirs {
            let angle = |w: DVec3| w.dot(v).clamp(-1.0, 1.0).acos();
            assert!(angle(decode_f32(encode_f32(v))) < 1e-6, "{v}");
            assert!(angle(decode_u32(encode_u32(v))) < 1e-4, "{v}");
            let (x, y) = encode(v);
            assert!((decode(x, y) - v).length() < 1e-12, "{v}");
        }
    }
}
